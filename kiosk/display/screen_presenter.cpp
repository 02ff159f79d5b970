// SPDX-License-Identifier: Apache-2.0
#include "kiosk/display/screen_presenter.h"

#include <algorithm>
#include <string>

#include "kiosk/display/projector_assignment.h"

namespace mogao {

Result<ScreenPresenter> ScreenPresenter::create(OutputBackend& backend, const ScreenCalibration& screen,
                                                std::vector<std::string>* notes) {
    std::vector<std::optional<std::size_t>> projector_of = assign_projectors(backend.outputs(), screen, notes);
    std::vector<OutputState> states(projector_of.size());
    std::vector<std::optional<std::size_t>> renderer_index(screen.projectors.size());
    std::vector<std::string> ids;
    bool any = false;
    for (std::size_t i = 0; i < projector_of.size(); ++i) {
        if (!projector_of[i]) continue;
        const std::size_t p = *projector_of[i];
        if (!renderer_index[p]) {
            auto added = backend.renderer().add_projector(screen.projectors[p]);
            if (!added) return with_context(added.error(), "projector '" + screen.projectors[p].id + "'");
            renderer_index[p] = *added;
            ids.resize(*added + 1);
            ids[*added] = screen.projectors[p].id;
        }
        states[i].lit = true;
        states[i].projector = *renderer_index[p];
        any = true;
    }
    if (!any) return make_error(EINVAL, "no output got a projector calibration");
    return ScreenPresenter(backend, std::move(projector_of), std::move(states), std::move(ids));
}

Status ScreenPresenter::swap_calibration(const ScreenCalibration& screen) {
    last_presents_ = 0;
    std::vector<const ProjectorCalibration*> next(renderer_ids_.size(), nullptr);
    for (std::size_t r = 0; r < renderer_ids_.size(); ++r) {
        for (const auto& p : screen.projectors) {
            if (p.id == renderer_ids_[r]) next[r] = &p;
        }
        if (next[r] == nullptr) {
            return make_error(EINVAL, "the new calibration has no projector '" + renderer_ids_[r] +
                                          "', which an output shows (a new layout needs a restart of the kiosk)");
        }
    }
    Status first_error;
    for (std::size_t r = 0; r < next.size(); ++r) {
        Status s = backend_->renderer().replace_projector(r, *next[r]);
        if (!s && first_error.ok()) first_error = with_context(s.error(), "projector '" + renderer_ids_[r] + "'");
    }
    if (!has_content_) return first_error;
    dirty_ = true;  // the current content through the new maps, as soon as no round is in flight
    if (Status s = present_round(); !s && first_error.ok()) first_error = s;
    return first_error;
}

Status ScreenPresenter::show(const Rgb8Image& content, std::uint64_t tag) {
    last_presents_ = 0;
    if (has_content_ && tag < tag_) return make_error(EINVAL, "content tags must not decrease");
    // Safe while a round is in flight: its outputs were drawn already; the next round reads this.
    if (Status s = backend_->renderer().set_content(content); !s) return s;
    has_content_ = true;
    dirty_ = true;
    tag_ = tag;
    return present_round();
}

Status ScreenPresenter::repaint() {
    last_presents_ = 0;
    if (!has_content_ || round_in_flight()) return {};
    dirty_ = true;
    return present_round();
}

Status ScreenPresenter::present_due() {
    last_presents_ = 0;
    return present_round();
}

Status ScreenPresenter::on_ready(const std::vector<std::size_t>& outputs) {
    last_presents_ = 0;
    for (const std::size_t i : outputs) {
        if (i >= states_.size() || !states_[i].in_flight) continue;
        states_[i].in_flight = false;  // its flip of the round completed
        states_[i].shown_tag = flight_tag_;
    }
    return present_round();  // once the whole round completed
}

bool ScreenPresenter::round_in_flight() const {
    return std::any_of(states_.begin(), states_.end(), [](const OutputState& o) { return o.in_flight; });
}

Status ScreenPresenter::present_round() {
    if (!dirty_ || round_in_flight()) return {};
    for (std::size_t i = 0; i < states_.size(); ++i) {
        if (states_[i].lit && !backend_->ready(i)) return {};  // a round starts on every output or on none
    }
    Status first_error;
    std::vector<std::size_t> staged;
    for (std::size_t i = 0; i < states_.size(); ++i) {
        const OutputState& o = states_[i];
        if (!o.lit) continue;
        Status s = backend_->begin_frame(i);
        if (s) s = backend_->renderer().draw(o.projector, backend_->outputs()[i].size);
        if (s) s = backend_->stage(i);
        if (!s) {
            if (first_error.ok()) first_error = with_context(s.error(), backend_->outputs()[i].name);
            continue;  // left out of this round; the next one retries it
        }
        staged.push_back(i);
        if (output_presented_) output_presented_();
    }
    if (staged.empty()) return first_error;
    if (Status s = backend_->commit_round(); !s) return with_context(s.error(), "round of " + std::to_string(tag_));
    dirty_ = false;
    last_presents_ = staged.size();
    flight_tag_ = tag_;
    for (const std::size_t i : staged) {
        // Ready again at once: synchronous (headless) or the blocking first modeset.
        if (backend_->ready(i)) states_[i].shown_tag = tag_;
        else states_[i].in_flight = true;
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
