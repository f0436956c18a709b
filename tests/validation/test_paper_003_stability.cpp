// Paper 003 (process damping in robotic milling, KR270), §3.3 Figure 4: the
// simulated half-immersion down-milling cut (Ktc 1600 MPa, Krc 600 MPa, 12 mm
// two-flute cutter, 0.05 mm/tooth) with the Tab. 1 modes the paper uses.
//
//   paper: "the region from 1000 rpm to 3000 rpm demonstrates significantly
//          low stability" governed by the robot modes (16-20 Hz, 48 Hz); the
//          tool mode (4-5 kHz) is suppressed by process damping after about
//          3500 rpm, the robot modes hindering the process-damped region.
//   ours : the zero-order envelope of one-mode diagrams with energy-balance
//          process damping (003 §3.2), from examples/003_*.yaml with
//          process.ae = 6 mm (half immersion).
//   checks: below 2000 rpm a robot mode (< 100 Hz) governs; at the top of the
//          range a tool mode governs, chattering at 4-5.5 kHz (the paper says
//          "near 4-5 kHz"; process damping lifts our chatter to ≈ 5.15 kHz).
//   disagreement, printed and left visible: we find the robot→tool transition
//          near 5300 rpm, the paper near 3000-3500 rpm. Its process-damping
//          parameters are not published (ours are 000's) and the result is
//          sensitive to them; see docs/validation.md.
//   assumptions: Ksp 1.5e14 N/m³, wear land 40 µm, μ 0.3 (from paper 000;
//          003 gives none); 003's Y modes along our feed axis x.

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <numbers>

#include "robomill/io/job.hpp"
#include "robomill/stability/lobes.hpp"
#include "robomill/stability/process_damping.hpp"

namespace {

using namespace robomill;

TEST(Paper003, RobotModesGovernLowSpeedsAndTheToolModeHighSpeeds) {
  const io::Job job =
      io::load_job(std::string(ROBOMILL_SOURCE_DIR) + "/examples/003_kr270_process_damping.yaml",
                   {{"process.ae", "6 mm"}});
  const stability::RegenerativeModel model(tool::Tool(*job.tool), *job.cutting, *job.process,
                                           io::modal_model(job));
  stability::ProcessDamping damping;
  damping.model = stability::ProcessDampingModel::energy_balance;
  damping.indentation_n_per_m3 = job.stability->indentation_n_per_m3;
  damping.wear_land_m = job.stability->wear_land_m;
  damping.friction = job.stability->friction;
  stability::ProcessDampedOptions options;
  options.method = stability::MultiModeMethod::envelope;
  options.zero_order.depth_max_m = 10e-3;
  options.threads = 0;
  const auto speeds = stability::linear_range(1000.0 * std::numbers::pi / 30.0,
                                              6000.0 * std::numbers::pi / 30.0, 51);
  const auto limits = stability::process_damped_limits(model, damping, speeds, options);
  double transition_rpm = 0.0;
  for (const auto& limit : limits) {
    const double rpm = limit.spindle_rad_s * 30.0 / std::numbers::pi;
    if (!limit.limited)
      continue;
    if (rpm < 2000.0) {
      EXPECT_LT(limit.chatter_frequency_hz, 100.0) << rpm << " rpm";
    }
    if (transition_rpm == 0.0 && limit.chatter_frequency_hz > 1000.0 && rpm > 2000.0) {
      transition_rpm = rpm;
    }
    if (static_cast<int>(std::lround(rpm)) % 1000 == 0) {
      std::cout << "[validation] 003 Fig 4 envelope: " << rpm << " rpm, limit "
                << limit.depth_limit_m * 1e3 << " mm, chatter " << limit.chatter_frequency_hz
                << " Hz (mode " << limit.mode + 1 << ")\n";
    }
  }
  ASSERT_TRUE(limits.back().limited);
  EXPECT_GT(limits.back().chatter_frequency_hz, 4000.0);
  EXPECT_LT(limits.back().chatter_frequency_hz, 5500.0);
  std::cout << "[validation] 003 Fig 4: the tool mode governs from " << transition_rpm
            << " rpm (paper: about 3000-3500 rpm)\n";
  EXPECT_GT(transition_rpm, 2000.0);
}

}  // namespace
