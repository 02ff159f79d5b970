// SPDX-License-Identifier: Apache-2.0
#include "kiosk/display/kiosk_display.h"

#include <algorithm>
#include <iterator>

#include <spdlog/spdlog.h>

#include "common/link_types.h"
#include "kiosk/display/connecting_screen.h"

namespace mogao {

Result<KioskDisplay> KioskDisplay::create(std::unique_ptr<OutputBackend> backend, ScreenCalibration screen,
                                          std::vector<std::string>* notes) {
    auto presenter = ScreenPresenter::create(*backend, screen, notes);
    if (!presenter) return presenter.error();
    return KioskDisplay(std::move(backend), std::move(presenter).value(), std::move(screen));
}

void KioskDisplay::take_off_indirect_light(IndirectLightSource source) {
    indirect_source_ = std::move(source);
    indirect_ = indirect_source_ ? indirect_source_(screen_) : std::nullopt;
    if (!indirect_) (void)backend_->renderer().set_indirect_light({});
}

void KioskDisplay::update_indirect_light(const Rgb8Image& content) {
    if (!indirect_) return;
    Status s =
        backend_->renderer().set_indirect_light(indirect_->field(content, backend_->renderer().content_transform()));
    if (!s) spdlog::warn("indirect light: {}", s.error().message);  // the last field stays in use
}

Status KioskDisplay::show_connecting_screen(ImageSize content, const std::string& endpoint) {
    return show_card(make_connecting_screen(content, "FARM " + endpoint));
}

Status KioskDisplay::show_card(const Rgb8Image& card) {
    set_content_transform({});  // the card is made for the screen itself
    update_indirect_light(card);
    if (Status s = presenter_.show(card, 0); !s) return s;
    account();
    return {};
}

void KioskDisplay::show(const ContentFrame& f) {
    pending_[f.request_id] = PresentedFrame{
        f.request_id,        f.link_frame_id, f.jpeg_bytes, f.times.request_ns, f.times.receive_ns, 0, f.decode_ms,
        stats_.rounds() + 1, f.image.size,    f.spp,        f.bounces};
    while (pending_.size() > kMaxPendingFrames) pending_.erase(pending_.begin());
    update_indirect_light(f.image);
    if (Status s = presenter_.show(f.image, f.request_id); !s) spdlog::warn("present: {}", s.error().message);
    account();
}

Status KioskDisplay::swap_calibration(ScreenCalibration screen) {
    Status s = presenter_.swap_calibration(screen);
    if (s) screen_ = std::move(screen);
    if (s && indirect_source_) take_off_indirect_light(indirect_source_);  // the new blends and models
    account();
    return s;
}

void KioskDisplay::refresh_content(const Rgb8Image& content) {
    update_indirect_light(content);
    if (Status s = presenter_.show(content, presenter_.current_tag()); !s) {
        spdlog::warn("present: {}", s.error().message);
    }
    account();
}

void KioskDisplay::repaint() {
    // Nothing while a round is in flight: its completion draws what is due. A recording draws an
    // unchanged frame again after k idle ticks without a round, so that a held frame (the farm down)
    // is still recorded; the other idle ticks draw only what changed, as without a recording: a round
    // on a software rasteriser takes tens of ms of the cores the farm may render on.
    const bool force = recorder_ && ++idle_ticks_ >= static_cast<std::uint64_t>(recorder_->every());
    Status s = force ? presenter_.repaint() : presenter_.present_due();
    if (!s) spdlog::warn("repaint: {}", s.error().message);
    account(force);
}

void KioskDisplay::set_content_transform(const ContentTransform& t) {
    if (t == backend_->renderer().content_transform()) return;
    backend_->renderer().set_content_transform(t);
    presenter_.invalidate();
}

Status KioskDisplay::on_flip() {
    auto ready = backend_->dispatch_events();
    if (!ready) return ready.error();
    if (Status s = presenter_.on_ready(*ready); !s) spdlog::warn("present: {}", s.error().message);
    account();
    return {};
}

void KioskDisplay::account(bool forced) {
    const auto now = std::chrono::steady_clock::now();
    busy_since_.resize(backend_->outputs().size());
    for (std::size_t i = 0; i < busy_since_.size(); ++i) {
        if (backend_->ready(i)) {
            busy_since_[i].reset();
        } else if (!busy_since_[i]) {
            busy_since_[i] = now;
        }
    }
    if (presenter_.last_presents() > 0) {
        stats_.display_round();
        idle_ticks_ = 0;
        if (recorder_) {
            try {
                recorder_->write_round(stats_.rounds(), presenter_.current_tag(), forced);
            } catch (const std::exception& e) {
                spdlog::warn("PNG output: {}", e.what());
            }
        }
    }
    while (const auto tag = presenter_.take_completed()) {
        const auto it = pending_.find(*tag);
        if (it == pending_.end()) continue;  // the connecting screen (tag 0)
        PresentedFrame done = it->second;
        done.presented_ns = on_screen_ns();
        stats_.presented(done);
        ++frames_on_screen_;
        pending_.erase(pending_.begin(), std::next(it));  // older ones were overtaken on some output
    }
}

std::int64_t KioskDisplay::on_screen_ns() const {
    // The round's latest output: KMS flip events of one commit may arrive a vblank apart.
    std::optional<std::int64_t> latest;
    const auto& projector_of = presenter_.projector_of();
    for (std::size_t i = 0; i < projector_of.size(); ++i) {
        if (!projector_of[i]) continue;
        const auto t = backend_->presented_ns(i);
        if (!t) return realtime_ns();  // the backend cannot tell: now, when the loop learnt it
        latest = latest ? std::max(*latest, *t) : *t;
    }
    return latest ? *latest : realtime_ns();
}

std::optional<std::size_t> KioskDisplay::overdue_output(std::chrono::steady_clock::time_point now,
                                                        std::chrono::steady_clock::duration timeout) {
    for (std::size_t i = 0; i < busy_since_.size(); ++i) {
        if (backend_->ready(i)) {
            busy_since_[i].reset();
        } else if (busy_since_[i] && now - *busy_since_[i] > timeout) {
            return i;
        }
    }
    return std::nullopt;
}

bool KioskDisplay::all_outputs_ready() const {
    for (std::size_t i = 0; i < backend_->outputs().size(); ++i) {
        if (!backend_->ready(i)) return false;
    }
    return true;
}

void KioskDisplay::write_composite() const {
    if (!recorder_) return;
    const auto file = recorder_->dir() / "screen-composite.png";
    try {
        recorder_->write_composite(screen_, presenter_.projector_of(), file);
        spdlog::info("composited screen: {}", file.string());
    } catch (const std::exception& e) {
        spdlog::warn("composited screen: {}", e.what());
    }
}

}  // namespace mogao
