// SPDX-License-Identifier: Apache-2.0
#include "kiosk/screen_presenter.h"

#include <algorithm>

#include "kiosk/projector_assignment.h"

namespace mogao {

Result<ScreenPresenter> ScreenPresenter::create(OutputBackend& backend, const ScreenCalibration& screen,
                                                std::vector<std::string>* notes) {
    std::vector<std::optional<std::size_t>> projector_of = assign_projectors(backend.outputs(), screen, notes);
    std::vector<OutputState> states(projector_of.size());
    std::vector<std::optional<std::size_t>> renderer_index(screen.projectors.size());
    bool any = false;
    for (std::size_t i = 0; i < projector_of.size(); ++i) {
        if (!projector_of[i]) continue;
        const std::size_t p = *projector_of[i];
        if (!renderer_index[p]) {
            auto added = backend.renderer().add_projector(screen.projectors[p]);
            if (!added) return with_context(added.error(), "projector '" + screen.projectors[p].id + "'");
            renderer_index[p] = *added;
        }
        states[i].lit = true;
        states[i].projector = *renderer_index[p];
        any = true;
    }
    if (!any) return make_error(EINVAL, "no output got a projector calibration");
    return ScreenPresenter(backend, std::move(projector_of), std::move(states));
}

Status ScreenPresenter::show(const Rgb8Image& content, std::uint64_t tag) {
    last_presents_ = 0;
    if (has_content_ && tag < tag_) return make_error(EINVAL, "content tags must not decrease");
    if (Status s = backend_->renderer().set_content(content); !s) return s;
    has_content_ = true;
    tag_ = tag;
    for (OutputState& o : states_) o.dirty = o.lit;
    return present_dirty();
}

Status ScreenPresenter::repaint() {
    last_presents_ = 0;
    if (!has_content_) return {};
    for (std::size_t i = 0; i < states_.size(); ++i) {
        if (states_[i].lit && !states_[i].in_flight && backend_->ready(i)) states_[i].dirty = true;
    }
    return present_dirty();
}

Status ScreenPresenter::on_ready(const std::vector<std::size_t>& outputs) {
    last_presents_ = 0;
    for (const std::size_t i : outputs) {
        if (i >= states_.size()) continue;
        OutputState& o = states_[i];
        if (o.in_flight) {
            o.in_flight = false;
            o.shown_tag = o.flight_tag;
        }
    }
    return present_dirty();
}

Status ScreenPresenter::present_dirty() {
    Status first_error;
    for (std::size_t i = 0; i < states_.size(); ++i) {
        OutputState& o = states_[i];
        if (!o.lit || !o.dirty || o.in_flight || !backend_->ready(i)) continue;
        Status s = backend_->begin_frame(i);
        if (s) s = backend_->renderer().draw(o.projector, backend_->outputs()[i].size);
        if (s) s = backend_->present(i);
        if (!s) {
            if (first_error.ok()) first_error = with_context(s.error(), backend_->outputs()[i].name);
            continue;
        }
        ++last_presents_;
        if (output_presented_) output_presented_();
        o.dirty = false;
        if (backend_->ready(i)) {
            o.shown_tag = tag_;  // synchronous (headless) or the blocking first modeset
        } else {
            o.in_flight = true;
            o.flight_tag = tag_;
        }
    }
    return first_error;
}

std::optional<std::uint64_t> ScreenPresenter::take_completed() {
    std::optional<std::uint64_t> oldest;
    for (const OutputState& o : states_) {
        if (!o.lit) continue;
        if (!o.shown_tag) return std::nullopt;
        oldest = oldest ? std::min(*oldest, *o.shown_tag) : *o.shown_tag;
    }
    if (!oldest || (completed_ && *oldest <= *completed_)) return std::nullopt;
    completed_ = oldest;
    return oldest;
}

}  // namespace mogao
