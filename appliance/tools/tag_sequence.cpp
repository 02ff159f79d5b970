// SPDX-License-Identifier: Apache-2.0
// mogao-tag-sequence's job: a synthetic hand-held tag sequence for replay (laboratory).
#include <cstdio>

#include "appliance/tools/track_commands.h"
#include "appliance/tracker/lab/hand_sequence.h"

namespace mogao::track {

int make_sequence(const SequenceOptions& o) {
    HandSequenceSpec spec;
    spec.seconds = o.seconds;
    spec.frames_per_second = o.fps;
    spec.family = o.family;
    spec.tag_id = o.id;
    spec.tag_size_m = o.tag_size_mm / 1000.0;
    spec.camera = ideal_camera(o.width, o.height, o.focal_px);
    spec.noise_sigma = o.noise;
    spec.seed = o.seed;
    write_hand_sequence(o.out, spec);
    std::printf("wrote %zu frames, timestamps.txt, camera.json and truth.json to %s\n", hand_trajectory(spec).size(),
                o.out.string().c_str());
    return 0;
}

}  // namespace mogao::track
