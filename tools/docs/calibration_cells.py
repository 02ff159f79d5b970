# SPDX-License-Identifier: Apache-2.0
"""Table cells both calibration doc scripts write from a `mogao-calibrate-sim rig` report.json, so that a column
means the same in the rig table and the unseen-rig table. Python 3 standard library only."""


def heights_cell(screen):
    """The told heights' check (report.json's screen.heights_check): content's mean / max shift, projector pixels,
    between the fit on the told span and the fit with the top edge free; a fitted screen is not checked."""
    h = screen.get("heights_check", {})
    if not h.get("tried"):
        return "fitted, not checked"
    return f"{h['shift_mean_px']:.3f} / {h['shift_max_px']:.3f}"


def seams_grid_phrase(reports):
    """How the seam figures of these reports were sampled (report.json's ground_truth.seams_grid), for a table's
    caption; the reports must agree, or the table would mix grids."""
    grids = {r["ground_truth"]["seams_grid"] for r in reports if r is not None}
    if len(grids) > 1:
        raise SystemExit(f"the reports' seam grids differ ({', '.join(sorted(grids))}); one table takes one grid")
    grid = grids.pop() if grids else "pixel-dense"
    if grid == "pixel-dense":
        return ("on a point per projector pixel where two projectors show content (pixel means at the 4096 seam "
                "points of largest deviation)")
    return f"on {grid.replace('x', ' x ')} content points"
