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
