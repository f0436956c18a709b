// The feed schedule (robot_path/feed_schedule.hpp) on measurements with a known
// answer: each line's loads follow a tooth force K_e b + K_c(h) h b with a
// size-dependent K_c ∝ h^-0.3 (004 Appendix A's form), so the cap's feed is
// known in closed form, while "force ∝ feed" is wrong; and the joint speeds
// scale exactly with the feed.

#include <gtest/gtest.h>

#include <cmath>

#include "robomill/core/error.hpp"
#include "robomill/robot_path/feed_schedule.hpp"

namespace robomill::robot_path {
namespace test_feed_schedule_cpp {
namespace {

// Line i: edge force E_i plus a cutting force C_i s^0.7 at feed scale s;
// the deflection 1 um per 10 N; the fastest joint w_i s.
struct LineLaw {
  double edge_n, cutting_n, joint_rad_s;
};

toolpath::Program program_of(const std::vector<LineLaw>& laws, double feed_m_s) {
  toolpath::Program program;
  program.dialect = "gcode";
  for (std::size_t i = 0; i < laws.size(); ++i) {
    toolpath::Move move;
    move.kind = toolpath::MotionKind::linear;
    move.feed_m_s = feed_m_s;
    move.line = static_cast<int>(10 + i);
    program.moves.push_back(move);
  }
  // A rapid that is never scheduled.
  toolpath::Move rapid;
  rapid.kind = toolpath::MotionKind::rapid;
  rapid.line = 99;
  program.moves.push_back(rapid);
  return program;
}

double force_at(const LineLaw& law, double scale) {
  return law.edge_n + law.cutting_n * std::pow(scale, 0.7);
}

// The scale at which the force equals `force`: (force − E) / C)^(1/0.7).
double scale_for(const LineLaw& law, double force) {
  return std::pow((force - law.edge_n) / law.cutting_n, 1.0 / 0.7);
}

struct Counting {
  std::vector<LineLaw> laws;
  int runs = 0;
  std::vector<MoveLoads> operator()(const std::vector<double>& scale) {
    ++runs;
    std::vector<MoveLoads> loads(laws.size() + 1);
    for (std::size_t i = 0; i < laws.size(); ++i) {
      loads[i].measured = laws[i].cutting_n > 0.0;
      if (loads[i].measured) {
        loads[i].force_peak_n = force_at(laws[i], scale[i]);
        loads[i].deflection_m = loads[i].force_peak_n * 1e-7;
      }
      loads[i].joint_speed_rad_s = laws[i].joint_rad_s * scale[i];
    }
    return loads;
  }
};

TEST(FeedSchedule, SlowsEachLineToItsForceCapAndMeasuresIt) {
  Counting measure{{{50.0, 900.0, 0.1}, {100.0, 300.0, 0.1}, {200.0, 1600.0, 0.1}}};
  const toolpath::Program program = program_of(measure.laws, 0.02);
  FeedLimits limits;
  limits.force_max_n = 600.0;
  const FeedSchedule schedule =
      schedule_feeds(program, limits, [&](const std::vector<double>& s) { return measure(s); });
  ASSERT_EQ(schedule.lines.size(), 3u);
  // Line 10: 950 N at the programmed feed, over the cap: slowed to the
  // closed-form scale within the search's tolerance, never above the cap.
  const LineFeed& first = schedule.lines[0];
  EXPECT_EQ(first.line, 10);
  EXPECT_NEAR(first.before.force_peak_n, 950.0, 1e-9);
  EXPECT_LE(first.after.force_peak_n, 600.0);
  EXPECT_GE(first.after.force_peak_n, 600.0 * (limits.target - limits.tolerance));
  EXPECT_NEAR(first.after.force_peak_n, force_at(measure.laws[0], first.scale), 1e-9);
  EXPECT_GT(first.scale, scale_for(measure.laws[0], 600.0 * (limits.target - limits.tolerance)));
  EXPECT_LE(first.scale, scale_for(measure.laws[0], 600.0));
  EXPECT_EQ(first.binding, "force");
  // "Force ∝ feed" would have stopped at 600/950 = 0.63, still over the cap.
  EXPECT_GT(force_at(measure.laws[0], 600.0 / 950.0), 600.0);
  // Line 11: 400 N, under the cap and no faster feed allowed: kept.
  EXPECT_EQ(schedule.lines[1].scale, 1.0);
  EXPECT_TRUE(schedule.lines[1].binding.empty());
  // Line 12: 1800 N.
  EXPECT_LE(schedule.lines[2].after.force_peak_n, 600.0);
  EXPECT_LT(schedule.lines[2].scale, first.scale);
  EXPECT_NEAR(schedule.max_before.force_peak_n, 1800.0, 1e-9);
  EXPECT_LE(schedule.max_after.force_peak_n, 600.0);
  EXPECT_EQ(schedule.runs, measure.runs);
  EXPECT_LE(schedule.runs, limits.max_runs);
}

TEST(FeedSchedule, SpeedsUpToFeedMaxOrTheCapAndKeepsJointSpeeds) {
  Counting measure{{{50.0, 200.0, 0.1}, {50.0, 200.0, 0.5}, {50.0, 20.0, 0.1}}};
  const toolpath::Program program = program_of(measure.laws, 0.01);  // 600 mm/min
  FeedLimits limits;
  limits.deflection_max_m = 40e-6;  // 400 N of force
  limits.joint_speed_max_rad_s = 0.6;
  limits.feed_max_m_s = 0.05;  // 3000 mm/min: scale 5
  const FeedSchedule schedule =
      schedule_feeds(program, limits, [&](const std::vector<double>& s) { return measure(s); });
  // Line 10: 250 N → the deflection cap at (350/200)^(1/0.7) = 2.22.
  EXPECT_GT(schedule.lines[0].scale, 1.5);
  EXPECT_LE(schedule.lines[0].after.deflection_m, 40e-6);
  EXPECT_GE(schedule.lines[0].after.deflection_m, 40e-6 * (limits.target - limits.tolerance));
  EXPECT_EQ(schedule.lines[0].binding, "deflection");
  // Line 11: the same loads, but a joint at 0.5 rad/s allows 1.2 × only.
  EXPECT_NEAR(schedule.lines[1].scale, 1.2, 1e-12);
  EXPECT_EQ(schedule.lines[1].binding, "joint_speed");
  EXPECT_NEAR(schedule.lines[1].after.joint_speed_rad_s, 0.6, 1e-12);
  // Line 12: light loads, to feed_max (the joint bound allows 6 ×).
  EXPECT_NEAR(schedule.lines[2].scale, 5.0, 1e-12);
  EXPECT_EQ(schedule.lines[2].binding, "feed_max");
  EXPECT_LE(schedule.lines[2].after.deflection_m, 40e-6);
}

TEST(FeedSchedule, ALineProgrammedFasterThanFeedMaxComesDownToIt) {
  Counting measure{{{10.0, 20.0, 0.1}}};                             // light loads
  const toolpath::Program program = program_of(measure.laws, 0.05);  // 3000 mm/min
  FeedLimits limits;
  limits.force_max_n = 600.0;
  limits.feed_max_m_s = 0.04;  // 2400 mm/min
  const FeedSchedule schedule =
      schedule_feeds(program, limits, [&](const std::vector<double>& s) { return measure(s); });
  EXPECT_NEAR(schedule.lines[0].scale, 0.8, 1e-12);
  EXPECT_EQ(schedule.lines[0].binding, "feed_max");
}

TEST(FeedSchedule, JointSpeedAloneSlowsLinesExactly) {
  Counting measure{{{0.0, 0.0, 1.0}, {0.0, 0.0, 0.2}}};  // no cut: joints only
  const toolpath::Program program = program_of(measure.laws, 0.02);
  FeedLimits limits;
  limits.joint_speed_max_rad_s = 0.5;
  const FeedSchedule schedule =
      schedule_feeds(program, limits, [&](const std::vector<double>& s) { return measure(s); });
  EXPECT_EQ(measure.runs, 1);  // exact: no search
  EXPECT_NEAR(schedule.lines[0].scale, 0.5, 1e-12);
  EXPECT_NEAR(schedule.lines[0].after.joint_speed_rad_s, 0.5, 1e-12);
  EXPECT_EQ(schedule.lines[1].scale, 1.0);
}

TEST(FeedSchedule, ACapNoFeedMeetsIsAnErrorNamingTheLine) {
  // Line 11's edge force alone (700 N) exceeds the 600 N cap at any feed.
  Counting measure{{{50.0, 400.0, 0.1}, {700.0, 300.0, 0.1}}};
  const toolpath::Program program = program_of(measure.laws, 0.02);
  FeedLimits limits;
  limits.force_max_n = 600.0;
  limits.feed_min_m_s = 0.005;  // 300 mm/min
  limits.job_line = 42;
  try {
    (void)schedule_feeds(program, limits, [&](const std::vector<double>& s) { return measure(s); });
    FAIL() << "expected an InputError";
  } catch (const InputError& error) {
    const std::string text = error.what();
    EXPECT_EQ(error.field(), "robot_path.feed_limits");
    EXPECT_EQ(error.line(), 42);
    EXPECT_NE(text.find("program line 11"), std::string::npos) << text;
    EXPECT_NE(text.find("force_max"), std::string::npos) << text;
    EXPECT_NE(text.find("feed_min 300.0 mm/min"), std::string::npos) << text;
  }
}

TEST(FeedSchedule, AJointBoundBelowFeedMinIsAnError) {
  Counting measure{{{0.0, 100.0, 2.0}}};
  const toolpath::Program program = program_of(measure.laws, 0.02);  // 1200 mm/min
  FeedLimits limits;
  limits.joint_speed_max_rad_s = 0.5;  // needs 300 mm/min
  limits.feed_min_m_s = 0.01;          // 600 mm/min
  EXPECT_THROW((void)schedule_feeds(program, limits,
                                    [&](const std::vector<double>& s) { return measure(s); }),
               InputError);
}

TEST(FeedSchedule, InconsistentLimitsAreRefused) {
  Counting measure{{{0.0, 100.0, 2.0}}};
  const toolpath::Program program = program_of(measure.laws, 0.02);
  const auto run = [&](const FeedLimits& limits) {
    return schedule_feeds(program, limits,
                          [&](const std::vector<double>& s) { return measure(s); });
  };
  EXPECT_THROW((void)run(FeedLimits{}), std::invalid_argument);  // no cap
  FeedLimits reversed;
  reversed.force_max_n = 100.0;
  reversed.feed_min_m_s = 0.02;
  reversed.feed_max_m_s = 0.01;
  EXPECT_THROW((void)run(reversed), std::invalid_argument);
}

}  // namespace
}  // namespace test_feed_schedule_cpp
}  // namespace robomill::robot_path
