// SPDX-License-Identifier: Apache-2.0
// Self-recalibration on the virtual rig against its ground truth (rig_simulation.h).
#include "appliance/selfcal/rig_simulation.h"

#include <gtest/gtest.h>

#include "appliance/rig/rig_file.h"

namespace mogao::selfcal {
namespace {

rig::VirtualRig standard() { return rig::load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/standard.toml"); }

TEST(SelfcalRig, Placeholder) { EXPECT_EQ(standard().projectors.size(), 3u); }

}  // namespace
}  // namespace mogao::selfcal
