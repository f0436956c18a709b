// The robot along the program with uncertain inputs (issue 33, deliverable
// 4; docs/uncertainty.md, "Along a program"): P(chatter) per sample is the
// fraction of draws whose own limit (the robot's modes of that draw at the
// sample's posture, the nominal run's shortcut) lies at or below the depth
// cut; checked against a closed form, against the draws' limits recomputed
// one by one, for monotony in the depth, for a tiny spread (the nominal
// verdict) and for the thread count.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "robomill/analysis/robot_path_setup.hpp"
#include "robomill/core/error.hpp"
#include "robomill/job/job.hpp"
#include "robomill/robot_path/robot_along_path.hpp"
#include "robomill/uncertainty/sample_statistics.hpp"
#include "support/kr270_cell.hpp"

namespace robomill::robot_path {
namespace test_path_draws_cpp {
namespace {

constexpr double kPi = std::numbers::pi;
const std::filesystem::path kSource = ROBOMILL_SOURCE_DIR;

job::Job cell_job(const std::string& extra) {
  return job::parse_job(support::kr270_cell_yaml() + extra, kSource / "tests" / "job.yaml");
}

std::string uncertainty_yaml(int samples, const std::string& variables) {
  return "uncertainty:\n  samples: " + std::to_string(samples) + "\n  seed: 7321\n  variables:\n" +
         variables;
}

// A common lognormal factor on all three shear coefficients: A0 scales by it
// (000 Eq 14), so every draw's zero-order limit is the nominal one over it.
std::string coefficient_factor(const std::string& sigma) {
  return "    - {name: coefficients, path: [cutting.Ktc, cutting.Krc, cutting.Kac], mode: scale, "
         "distribution: lognormal, sigma: " +
         sigma + "}\n";
}

// The robot drawn: a common factor on the six joint stiffnesses and one on
// the modal damping ratio (the modes move at every posture).
const std::string kRobotVariables =
    "    - {name: stiffness, path: robot.joint_stiffness, mode: scale, distribution: lognormal, "
    "sigma: 0.25}\n"
    "    - {name: damping, path: robot.damping_ratio, mode: scale, distribution: lognormal, "
    "sigma: 0.35}\n";

// A sample of a down-milling side cut along +x (ae 2.5 mm of a 10 mm
// cutter) at 8300 rpm.
toolpath::PathSample side_cut(double x_m, double ap_m, int line) {
  return support::side_cut_sample(x_m, kPi - std::acos(1.0 - 2.5 / 5.0), kPi, line, ap_m, 8300.0);
}

struct Cell {
  job::Job job;
  analysis::RobotPathSetup setup;
  analysis::RobotPathDraws draws;
  toolpath::Tooling tooling;
  explicit Cell(const std::string& extra)
      : job(cell_job(extra)),
        setup(std::move(*analysis::robot_path_setup(job, 2))),
        draws(analysis::robot_path_draws(job, 2)) {
    tooling.emplace(0, tool::Tool(*job.tool));
  }
  // The nominal analysis; the caller sets the draws (set_draws).
  RobotAlongPath along(int threads = 2) const {
    RobotPathSettings settings = setup.settings;
    settings.threads = threads;
    return RobotAlongPath(*setup.model, setup.structure, tooling, *job.cutting, setup.stability,
                          settings);
  }
};

}  // namespace

// Closed form: with X a common lognormal factor (median 1, σ of its log) on
// Ktc, Krc and Kac, draw d's limit at every sample is a/X_d, a the nominal
// limit there (the shortcut's decisions are relative, so the same samples
// are exact for every draw and interpolation commutes with 1/X). A sample
// cutting ap chatters in draw d when X_d ≥ a/ap: P = ½ erfc(ln(a/ap)/(σ√2)).
// Checked: the count against the factors themselves (exact up to ties), the
// probability against the closed form within 4 standard errors, and the
// band's quantiles against those of a/X_d.
TEST(PathDraws, CommonCuttingFactorGivesTheClosedFormProbability) {
  const double sigma = 0.2;
  Cell cell("robot_path: {tolerance: 1 %, max_span: 16, check_every: 4}\n" +
            uncertainty_yaml(48, coefficient_factor("0.2")));
  // The nominal limits first, then depths from 0.75 to 1.35 times them
  // (A0 and so the limits do not depend on ap).
  std::vector<toolpath::PathSample> samples;
  for (int i = 0; i < 18; ++i)
    samples.push_back(side_cut((5.0 + 2.3 * i) * 1e-3, 1e-3, 10 + i / 6));
  RobotAlongPath probe = cell.along();
  std::vector<RobotSample> nominal(samples.size());
  probe.evaluate(samples, nominal);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    ASSERT_TRUE(nominal[i].stability && nominal[i].limited) << i;
    samples[i].axial_depth_m =
        nominal[i].depth_limit_m * (0.75 + 0.6 * static_cast<double>(i) / 17.0);
  }
  RobotAlongPath along = cell.along();
  along.set_draws(cell.draws.path_draws());
  std::vector<RobotSample> out(samples.size());
  along.evaluate(samples, out);
  const Eigen::VectorXd factors = cell.draws.draws.values.col(0);
  const double n = static_cast<double>(factors.size());
  std::vector<double> sorted_factors(factors.begin(), factors.end());
  std::sort(sorted_factors.begin(), sorted_factors.end(), std::greater<>());
  int interior = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    SCOPED_TRACE("sample " + std::to_string(i));
    ASSERT_TRUE(out[i].drawn);
    const double a = out[i].depth_limit_m, ap = samples[i].axial_depth_m;
    EXPECT_EQ(out[i].depth_limit_m, nominal[i].depth_limit_m) << "the nominal limit is kept";
    std::vector<double> scaled;
    int chatter = 0, ties = 0;
    for (Eigen::Index d = 0; d < factors.size(); ++d) {
      scaled.push_back(a / factors[d]);
      const double ratio = a / (factors[d] * ap);
      ties += std::abs(ratio - 1.0) < 1e-9 ? 1 : 0;
      chatter += ratio <= 1.0 ? 1 : 0;
    }
    EXPECT_NEAR(out[i].p_chatter * n, chatter, ties);
    const double closed = 0.5 * std::erfc(std::log(a / ap) / (sigma * std::sqrt(2.0)));
    const double se = std::sqrt(closed * (1.0 - closed) / n);
    EXPECT_NEAR(out[i].p_chatter, closed, 4.0 * se + 1.0 / n)
        << "ap/a " << ap / a << ", closed form " << closed;
    EXPECT_NEAR(out[i].p_chatter_se, std::sqrt(out[i].p_chatter * (1.0 - out[i].p_chatter) / n),
                1e-15);
    interior += closed > 0.1 && closed < 0.9 ? 1 : 0;
    const double q05 = uncertainty::empirical_quantile(scaled, 0.05).value;
    const double q95 = uncertainty::empirical_quantile(scaled, 0.95).value;
    EXPECT_NEAR(out[i].depth_limit_q05_m, q05, 1e-9 * q05);
    EXPECT_NEAR(out[i].depth_limit_q95_m, q95, 1e-9 * q95);
    // The limit at the 5 % bound: with 48 draws ⌊0.05 · 48⌋ = 2 may chatter,
    // so it is a over the third largest factor, at every sample the same
    // fraction of the nominal limit (what --optimize scales a candidate's
    // limit by is exact here).
    const double bound = a / sorted_factors[2];
    EXPECT_NEAR(out[i].depth_limit_at_bound_m, bound, 1e-9 * bound);
    EXPECT_EQ(out[i].at_risk_drawn, ap >= out[i].depth_limit_at_bound_m);
    EXPECT_EQ(out[i].at_risk_drawn, out[i].p_chatter > 0.05) << "at risk: P over the bound";
  }
  EXPECT_GT(interior, 4) << "the depths should sweep through the band";
  const RobotPathSummary summary = along.finish();
  // Σ p over the samples is the mean count of chattering samples per draw.
  double sum = 0.0;
  for (const RobotSample& r : out)
    sum += r.p_chatter;
  EXPECT_NEAR(summary.expected_chatter_samples, sum, 1e-9 * sum);
  EXPECT_GT(summary.expected_chatter_samples_se, 0.0);
  EXPECT_EQ(summary.draws, 48u);
  EXPECT_GT(summary.draw_exact_limits, 0u);
}

// The robot itself drawn (joint stiffness and damping): at every sample of
// a cut whose depth steps up at three places along the part, P(chatter) is
// the fraction of the draws' limits recomputed directly (every sample exact
// here: max_span 1) at or below the depth, never decreasing with the depth
// at one place; the band holds the draws' quantiles and the nominal limit;
// the thread count changes nothing.
TEST(PathDraws, RobotDrawsAreEachDrawsOwnLimitAtThePosture) {
  Cell cell("robot_path: {max_span: 1, max_chatter_probability: 0.19}\n" +
            uncertainty_yaml(12, kRobotVariables));
  const std::vector<double> depths_mm = {0.37, 0.81, 1.29, 1.93, 2.71};
  std::vector<toolpath::PathSample> samples;
  for (int place = 0; place < 3; ++place)
    for (const double ap_mm : depths_mm)
      samples.push_back(side_cut((7.0 + 9.3 * place) * 1e-3, ap_mm * 1e-3, 20 + place));
  RobotAlongPath along = cell.along(), single = cell.along(1);
  along.set_draws(cell.draws.path_draws());
  single.set_draws(cell.draws.path_draws());
  std::vector<RobotSample> out(samples.size()), one_thread(samples.size());
  along.evaluate(samples, out);
  single.evaluate(samples, one_thread);
  const std::size_t n = cell.draws.setups.size();
  int inside = 0, between = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    SCOPED_TRACE("sample " + std::to_string(i));
    ASSERT_TRUE(out[i].drawn && out[i].exact);
    std::vector<double> limits;
    int chatter = 0;
    for (std::size_t d = 0; d < n; ++d) {
      const double limit = along.draw_limit(d, samples[i], out[i].q_rad).depth_limit_m;
      limits.push_back(limit);
      chatter += samples[i].axial_depth_m >= limit ? 1 : 0;
    }
    EXPECT_EQ(out[i].p_chatter, static_cast<double>(chatter) / static_cast<double>(n));
    // The limit at the 19 % bound: ⌊0.19 · 12⌋ = 2 draws may chatter, so
    // the third smallest; P(chatter) within the bound exactly below it.
    std::vector<double> sorted = limits;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(out[i].depth_limit_at_bound_m, sorted[2]);
    EXPECT_EQ(out[i].at_risk_drawn, out[i].p_chatter > 0.19);
    EXPECT_EQ(out[i].depth_limit_q05_m, uncertainty::empirical_quantile(limits, 0.05).value);
    EXPECT_EQ(out[i].depth_limit_q95_m, uncertainty::empirical_quantile(limits, 0.95).value);
    inside += out[i].depth_limit_q05_m <= out[i].depth_limit_m &&
                      out[i].depth_limit_m <= out[i].depth_limit_q95_m
                  ? 1
                  : 0;
    between += out[i].p_chatter > 0.0 && out[i].p_chatter < 1.0 ? 1 : 0;
    if (i % depths_mm.size() != 0) {
      EXPECT_GE(out[i].p_chatter, out[i - 1].p_chatter) << "deeper, not less likely to chatter";
    }
    EXPECT_EQ(out[i].p_chatter, one_thread[i].p_chatter);
    EXPECT_EQ(out[i].depth_limit_q05_m, one_thread[i].depth_limit_q05_m);
  }
  EXPECT_EQ(inside, static_cast<int>(samples.size())) << "the nominal limit inside the band";
  EXPECT_GT(between, 0) << "some depth should lie inside the band";
  const RobotPathSummary a = along.finish(), b = single.finish();
  EXPECT_EQ(a.draw_chatter_samples, b.draw_chatter_samples);
  EXPECT_EQ(a.expected_chatter_samples, b.expected_chatter_samples);
}

// A tiny spread (σ 1e-9): every draw's limit is the nominal one to 1e-6
// relative, so P(chatter) is the nominal verdict wherever the depth is not
// within 1e-6 of the limit, and the band closes on the nominal limit.
TEST(PathDraws, TinySpreadGivesTheNominalVerdict) {
  Cell cell("robot_path: {tolerance: 2 %, max_span: 8}\n" +
            uncertainty_yaml(16, coefficient_factor("1e-9")));
  std::vector<toolpath::PathSample> samples;
  for (int i = 0; i < 24; ++i)
    samples.push_back(side_cut((8.0 + 1.7 * i) * 1e-3, (0.4 + 0.21 * i) * 1e-3, 30 + i / 6));
  RobotAlongPath along = cell.along();
  along.set_draws(cell.draws.path_draws());
  std::vector<RobotSample> out(samples.size());
  along.evaluate(samples, out);
  int chatter = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    SCOPED_TRACE("sample " + std::to_string(i));
    const double a = out[i].depth_limit_m;
    EXPECT_NEAR(out[i].depth_limit_q05_m, a, 1e-6 * a);
    EXPECT_NEAR(out[i].depth_limit_q95_m, a, 1e-6 * a);
    if (std::abs(samples[i].axial_depth_m - a) > 1e-6 * a) {
      EXPECT_EQ(out[i].p_chatter, out[i].chatter ? 1.0 : 0.0);
    }
    chatter += out[i].chatter ? 1 : 0;
  }
  EXPECT_GT(chatter, 0);
  EXPECT_LT(chatter, static_cast<int>(samples.size()));
  const RobotPathSummary summary = along.finish();
  EXPECT_EQ(summary.expected_chatter_samples, static_cast<double>(summary.chatter));
  // The lines over 5 % are exactly the lines with a nominal chatter sample.
  std::vector<int> chatter_lines;
  for (std::size_t i = 0; i < samples.size(); ++i)
    if (out[i].chatter && (chatter_lines.empty() || chatter_lines.back() != samples[i].line))
      chatter_lines.push_back(samples[i].line);
  std::vector<int> listed;
  for (const RiskyLine& l : summary.risky_lines)
    listed.push_back(l.line);
  EXPECT_EQ(listed, chatter_lines);
}

// What moves the postures or the cut cannot be drawn along a program: the
// variable is named with its path.
TEST(PathDraws, KinematicsAndTheCutAreRefusedByName) {
  // The job's path (dots inside a flow map) and the reader's bracket form.
  for (const auto& [written, path] :
       {std::pair{"robot.dh.1.a", "robot.dh[1].a"}, std::pair{"tool.diameter", "tool.diameter"},
        std::pair{"robot.joints.2.upper", "robot.joints[2].upper"}}) {
    const job::Job job =
        cell_job(uncertainty_yaml(8, std::string("    - {name: reach, path: ") + written +
                                         ", distribution: normal, sd: 1 %}\n"));
    try {
      analysis::robot_path_draws(job, 1);
      ADD_FAILURE() << path << " was accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), "uncertainty.variables[0].path");
      EXPECT_NE(std::string(e.what()).find(std::string("'reach' sets ") + path), std::string::npos)
          << e.what();
    }
  }
  // Structure and coefficients are accepted.
  EXPECT_NO_THROW(analysis::robot_path_draws(
      cell_job(uncertainty_yaml(
          4, kRobotVariables +
                 "    - {name: c, path: robot.links.2.mass, distribution: uniform, min: 180 kg, "
                 "max: 220 kg}\n")),
      1));
}

// The drawn fields travel between processes (analysis::BlockSharing) bit for
// bit.
TEST(PathDraws, DrawnFieldsArePackedAndUnpacked) {
  RobotSample r;
  r.reachable = r.stability = r.drawn = true;
  r.depth_limit_m = 1.7e-3;
  r.p_chatter = 0.3125;
  r.p_chatter_se = std::sqrt(0.3125 * 0.6875 / 16.0);
  r.depth_limit_q05_m = 1.1e-3;
  r.depth_limit_q95_m = 2.9e-3;
  r.depth_limit_at_bound_m = 1.23e-3;
  r.at_risk_drawn = true;
  r.q_rad = RobotSample::Joints::LinSpaced(6, -1.0, 1.0);
  std::vector<double> packed(packed_size(6));
  pack(r, 6, packed.data());
  const RobotSample back = unpack(packed.data(), 6);
  EXPECT_TRUE(back.drawn);
  EXPECT_EQ(back.p_chatter, r.p_chatter);
  EXPECT_EQ(back.p_chatter_se, r.p_chatter_se);
  EXPECT_EQ(back.depth_limit_q05_m, r.depth_limit_q05_m);
  EXPECT_EQ(back.depth_limit_q95_m, r.depth_limit_q95_m);
  EXPECT_EQ(back.depth_limit_at_bound_m, r.depth_limit_at_bound_m);
  EXPECT_TRUE(back.at_risk_drawn);
  EXPECT_EQ(back.q_rad, r.q_rad);
}

}  // namespace test_path_draws_cpp
}  // namespace robomill::robot_path
