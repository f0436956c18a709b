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

#include "robomill/job/job.hpp"
#include "robomill/stability/lobes.hpp"
#include "robomill/stability/process_damping.hpp"
#include "support/validation_record.hpp"

namespace test_paper_003_stability_cpp {

namespace {

using namespace robomill;

/// 003 §3.1's energy-balance process damping with the job's Ksp, wear land, μ.
stability::ProcessDamping energy_balance_damping(const job::Job& job) {
  stability::ProcessDamping damping;
  damping.model = stability::ProcessDampingModel::energy_balance;
  damping.indentation_n_per_m3 = job.stability->indentation_n_per_m3;
  damping.wear_land_m = job.stability->wear_land_m;
  damping.friction = job.stability->friction;
  return damping;
}

TEST(Paper003, RobotModesGovernLowSpeedsAndTheToolModeHighSpeeds) {
  const job::Job job =
      job::load_job(std::string(ROBOMILL_SOURCE_DIR) + "/examples/003_kr270_process_damping.yaml",
                    {{"process.ae", "6 mm"}});
  const stability::RegenerativeModel model(tool::Tool(*job.tool), *job.cutting, *job.process,
                                           job::modal_model(job));
  const stability::ProcessDamping damping = energy_balance_damping(job);
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
  const char* assumptions = "Ksp 1.5e14 N/m^3, wear land 40 um, mu 0.3 (000's; 003 gives none)";
  test::record_check(
      "003", "Fig. 4", "chatter frequency at 6000 rpm (tool mode)", "Hz", "4000-5000",
      test::sig4(limits.back().chatter_frequency_hz), "4000 … 5500",
      limits.back().chatter_frequency_hz > 4000.0 && limits.back().chatter_frequency_hz < 5500.0,
      assumptions);
  test::record_check("003", "Fig. 4", "robot-to-tool transition speed", "rpm", "3000-3500",
                     test::sig4(transition_rpm), "> 2000 (known disagreement)",
                     transition_rpm > 2000.0, assumptions);
}

// 003 Table 2 and §4, the slot tests of examples/003_kr270_process_damping.yaml
// (ZOA, energy-balance process damping, our assumed Ksp/wear land/μ).
//   paper: dominant structure per test speed — robot at 1660 and 2300 rpm,
//          tool at 3210, 4490 and 5300 rpm; at 1660 rpm stable at 0.25-0.75 mm,
//          chatter at 1.0 mm, "robot modes 1 and 2 dominate".
//   ours : which structure sets the limit (chatter below 100 Hz: robot; above
//          1 kHz: tool) in the coupled all-mode diagram and in the paper's
//          envelope of one-mode diagrams, printed per speed; the 1660 rpm
//          verdicts against both.
//   why they disagree at 1660 rpm (checked below, not tuned): in a slot the
//          direct terms of the mean directional matrix are ∝ Krc while the
//          cross terms are ∝ Ktc (2.7 times larger), so a lone mode in x or y
//          sees a weak coupling and the envelope puts the limit at 2.2 mm
//          (mode Y2, 47 Hz), missing the 1.0 mm chatter; the near-equal robot
//          modes X1 (19.9 Hz, along y) and Y1 (17.8 Hz, along x) couple through
//          the cross terms and alone bring the limit to ≈ 0.2 mm at ≈ 20 Hz,
//          which the coupled diagram reproduces: it calls 0.25-0.75 mm
//          unstable. The truth (0.75-1.0 mm) lies between the two diagrams.
TEST(Paper003, Table2SlotTestsAgainstTheCoupledDiagramAndTheEnvelope) {
  const job::Job job =
      job::load_job(std::string(ROBOMILL_SOURCE_DIR) + "/examples/003_kr270_process_damping.yaml");
  const dynamics::ModalModel modes = job::modal_model(job);
  auto model_of = [&](const dynamics::ModalModel& m) {
    return stability::RegenerativeModel(tool::Tool(*job.tool), *job.cutting, *job.process, m);
  };
  const stability::ProcessDamping damping = energy_balance_damping(job);
  stability::ProcessDampedOptions options;
  options.zero_order.depth_max_m = 10e-3;
  auto limit_at = [&](const dynamics::ModalModel& m, stability::MultiModeMethod method,
                      double rpm) {
    options.method = method;
    return stability::process_damped_limits(model_of(m), damping, {rpm * std::numbers::pi / 30.0},
                                            options)[0];
  };
  auto structure = [](const stability::ZeroOrderLimit& l) {
    return !l.limited ? "none" : l.chatter_frequency_hz < 100.0 ? "robot" : "tool";
  };
  const struct {
    double rpm;
    const char* paper;
  } table2[] = {{1660, "robot"}, {2300, "robot"}, {3210, "tool"}, {4490, "tool"}, {5300, "tool"}};
  int coupled_agree = 0, envelope_agree = 0;
  for (const auto& row : table2) {
    const auto coupled = limit_at(modes, stability::MultiModeMethod::coupled, row.rpm);
    const auto envelope = limit_at(modes, stability::MultiModeMethod::envelope, row.rpm);
    coupled_agree += std::string(structure(coupled)) == row.paper;
    envelope_agree += std::string(structure(envelope)) == row.paper;
    std::cout << "[validation] 003 Tab 2, " << row.rpm << " rpm: paper " << row.paper
              << "; coupled " << coupled.depth_limit_m * 1e3 << " mm at "
              << coupled.chatter_frequency_hz << " Hz (" << structure(coupled) << "); envelope "
              << envelope.depth_limit_m * 1e3 << " mm at " << envelope.chatter_frequency_hz
              << " Hz (" << structure(envelope) << ", mode " << envelope.mode + 1 << ")\n";
  }
  std::cout << "[validation] 003 Tab 2 dominant structure: coupled agrees at " << coupled_agree
            << " of 5 speeds, envelope at " << envelope_agree << " of 5\n";
  // The robot modes govern the lowest test speed in both diagrams, the tool
  // the highest (the paper's trend); in between our transition depends on
  // the unpublished process-damping parameters (docs/validation.md).
  const auto coupled_1660 = limit_at(modes, stability::MultiModeMethod::coupled, 1660);
  const auto envelope_1660 = limit_at(modes, stability::MultiModeMethod::envelope, 1660);
  EXPECT_STREQ(structure(coupled_1660), "robot");
  EXPECT_STREQ(structure(envelope_1660), "robot");
  EXPECT_STREQ(structure(limit_at(modes, stability::MultiModeMethod::coupled, 5300)), "tool");
  EXPECT_STREQ(structure(limit_at(modes, stability::MultiModeMethod::envelope, 5300)), "tool");
  // The 1660 rpm verdicts bracket the truth between the two diagrams.
  EXPECT_LT(coupled_1660.depth_limit_m, 0.75e-3);
  EXPECT_GT(envelope_1660.depth_limit_m, 1.0e-3);
  // The reason: the X1 + Y1 pair alone (modes 1 and 4 of the job) already
  // calls the shallowest stable test (0.25 mm) unstable and chatters near
  // their frequencies, while each of them alone is over 5 times stiffer in
  // this slot. (The pair's 0.17 mm is 18 % below the all-mode 0.20 mm: the
  // other modes shift the phase of the coupled receptance a little.)
  const auto pair = limit_at(modes.subset({0, 3}), stability::MultiModeMethod::coupled, 1660);
  const auto x1 = limit_at(modes.subset({0}), stability::MultiModeMethod::coupled, 1660);
  const auto y1 = limit_at(modes.subset({3}), stability::MultiModeMethod::coupled, 1660);
  std::cout << "[validation] 003 at 1660 rpm: X1+Y1 together " << pair.depth_limit_m * 1e3
            << " mm at " << pair.chatter_frequency_hz << " Hz; X1 alone " << x1.depth_limit_m * 1e3
            << " mm, Y1 alone " << y1.depth_limit_m * 1e3 << " mm\n";
  EXPECT_LT(pair.depth_limit_m, 0.25e-3);
  EXPECT_GT(pair.chatter_frequency_hz, 15.0);
  EXPECT_LT(pair.chatter_frequency_hz, 25.0);
  EXPECT_GT(std::min(x1.depth_limit_m, y1.depth_limit_m), 5.0 * pair.depth_limit_m);
  const char* assumptions = "ZOA; energy-balance process damping with 000's Ksp, wear land, mu";
  test::record_check(
      "003", "Tab. 2, 1660 rpm", "dominant structure (coupled / envelope)", "", "robot",
      std::string(structure(coupled_1660)) + " / " + structure(envelope_1660), "robot in both",
      std::string(structure(coupled_1660)) == "robot" &&
          std::string(structure(envelope_1660)) == "robot",
      assumptions);
  test::record_check("003", "Tab. 2, 1660 rpm", "limit, coupled diagram", "mm",
                     "0.75-1.0 (stable 0.75, chatter 1.0)",
                     test::sig4(coupled_1660.depth_limit_m * 1e3), "< 0.75 (brackets the truth)",
                     coupled_1660.depth_limit_m < 0.75e-3, assumptions);
  test::record_check("003", "Tab. 2, 1660 rpm", "limit, envelope of one-mode diagrams", "mm",
                     "0.75-1.0 (stable 0.75, chatter 1.0)",
                     test::sig4(envelope_1660.depth_limit_m * 1e3), "> 1.0 (brackets the truth)",
                     envelope_1660.depth_limit_m > 1.0e-3, assumptions);
  test::record_check("003", "Tab. 2, 1660 rpm", "chatter frequency of modes X1+Y1", "Hz",
                     "17.8-19.9 (modes X1, Y1)", test::sig4(pair.chatter_frequency_hz), "15 … 25",
                     pair.chatter_frequency_hz > 15.0 && pair.chatter_frequency_hz < 25.0,
                     assumptions);
}

}  // namespace

}  // namespace test_paper_003_stability_cpp
