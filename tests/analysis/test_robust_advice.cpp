// analysis::robust_cutting_advice (issue 33, deliverable 3): the advice that
// keeps P(chatter) over the draws at most advise.max_chatter_probability,
// against the draws themselves, against the closed form of a common factor
// on the cutting coefficients, and against the nominal advice when the
// spread vanishes.
//
// The job is a two-mode tool tip (x 703 Hz, y 761 Hz) in quarter immersion
// by the zero-order method, advised over 4 000-13 000 rpm in 0.037 mm depth
// steps (a step no limit is a round multiple of), with the margin 1 so that
// the nominal advice keeps to the nominal limit itself.

#include "robomill/analysis/robust_advice.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "robomill/analysis/cutting_parameter_advice.hpp"
#include "robomill/core/error.hpp"
#include "robomill/job/job.hpp"
#include "robomill/stability/regenerative_model.hpp"
#include "robomill/tool/tool.hpp"
#include "support/two_mode_tool_tip.hpp"

namespace test_robust_advice_cpp {

namespace ra = robomill::analysis;
namespace job = robomill::job;
namespace rp = robomill::planning;

namespace {

std::string advice_yaml(const std::string& advise_extra, const std::string& uncertainty) {
  return "name: robust advice test\n" + robomill::test::two_mode_tool_tip_yaml() +
         "advise:\n"
         "  speeds: {from: 4000 rpm, to: 13000 rpm, count: 37}\n"
         "  refine: 6\n"
         "  depth_max: 30 mm\n"
         "  depth_step: 0.037 mm\n"
         "  margin: 1\n"
         "  method: zoa\n" +
         advise_extra + uncertainty;
}

std::string common_factor(int samples, const std::string& sigma) {
  return "uncertainty:\n  samples: " + std::to_string(samples) +
         "\n  seed: 11\n  sampling: random\n  variables:\n"
         "    - {name: cutting_scale, path: [cutting.Ktc, cutting.Krc], mode: scale, "
         "distribution: lognormal, sigma: " +
         sigma + "}\n";
}

job::Job parse(const std::string& text) {
  return job::parse_job(text, "robust_advice_test.yaml");
}

/// The scan's rows of stage 0 (the speed grid both advices share), by speed.
std::vector<rp::SpeedAdvice> scanned(const rp::CuttingAdvice& advice) {
  std::vector<rp::SpeedAdvice> rows;
  for (const rp::SpeedAdvice& a : advice.scan)
    if (a.stage == 0)
      rows.push_back(a);
  return rows;
}

}  // namespace

// With X a common factor on Ktc and Krc every draw's limit is a_nominal(Ω)/X
// (test_stability_band.cpp's closed form), so the robust limit, the
// (⌊p n⌋ + 1)-th smallest draw limit, is a_nominal(Ω) / X_(n − ⌊p n⌋) (that
// order statistic of the factors, counted from the smallest) at every speed:
// one constant ratio, computed here from the draws themselves. p = 7 % of
// 300 draws allows ⌊21⌋ = 21 draws to chatter.
TEST(RobustAdvice, CommonCuttingFactorLowersEveryLimitByTheSameOrderStatistic) {
  const job::Job job =
      parse(advice_yaml("  max_chatter_probability: 7 %\n", common_factor(300, "0.2")));
  const ra::CuttingParameterAdvice nominal = ra::cutting_parameter_advice(job, 2);
  const ra::RobustCuttingAdvice robust = ra::robust_cutting_advice(job, nominal.advice, 2);
  ASSERT_EQ(robust.draw_count, 300);
  EXPECT_DOUBLE_EQ(robust.max_chatter_probability, 0.07);

  std::vector<double> factors(300);
  for (int i = 0; i < 300; ++i)
    factors[static_cast<std::size_t>(i)] = robust.draws.values(i, 0);
  std::sort(factors.begin(), factors.end());
  const double ratio = 1.0 / factors[300 - 21 - 1];  // the 22nd largest factor

  const std::vector<rp::SpeedAdvice> a = scanned(nominal.advice);
  const std::vector<rp::SpeedAdvice> r = scanned(robust.advice);
  ASSERT_EQ(a.size(), 37u);
  ASSERT_EQ(r.size(), 37u);
  int compared = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    SCOPED_TRACE("speed " + std::to_string(a[k].spindle_rad_s));
    EXPECT_EQ(r[k].spindle_rad_s, a[k].spindle_rad_s);
    if (!a[k].limited || a[k].limit_depth_m * ratio > 30e-3)
      continue;
    ++compared;
    EXPECT_NEAR(r[k].limit_depth_m, a[k].limit_depth_m * ratio, 1e-9 * a[k].limit_depth_m);
    // The depth is the largest 0.037 mm multiple under the robust limit.
    EXPECT_LE(r[k].depth_m, r[k].limit_depth_m);
    EXPECT_GT(r[k].depth_m + 0.037e-3, r[k].limit_depth_m);
  }
  EXPECT_GT(compared, 30);
  // The constant against its distribution: 1/X is lognormal (median 1,
  // sigma 0.2), its 7 % quantile exp(−0.2 · 1.4758) = 0.7445; the order
  // statistic of 300 draws has a standard error of about
  // √(p(1−p)/n) / density = 0.0147 / (φ(1.4758)/(0.2 · 0.7445)) ≈ 0.0164.
  std::printf("robust/nominal limit ratio %.5f (7 %% quantile of 1/X: %.5f)\n", ratio,
              std::exp(-0.2 * 1.4757910281791713));
  EXPECT_NEAR(ratio, std::exp(-0.2 * 1.4757910281791713), 3.0 * 0.0164);
}

// The advised point's probability, from the draws: at most p, and one depth
// step deeper more than p (the advice is the deepest step the bound allows;
// no offset limit here, and the advice lies far below depth_max). With the
// common factor, draw i chatters at depth d where a_nominal(Ω)/X_i < d, i.e.
// X_i > a_nominal(Ω)/d: recounted here from the factors, with a_nominal from
// the planner's own limit curve at the advised speed. The nominal advice,
// at the nominal limit itself (margin 1), chatters wherever X_i exceeds
// a_nominal/ap ≥ 1: in somewhat under half the draws.
TEST(RobustAdvice, AdvisedPointKeepsTheBoundAndTheNextStepBreaksIt) {
  const job::Job job = parse(advice_yaml("", common_factor(200, "0.25")));
  const ra::CuttingParameterAdvice nominal = ra::cutting_parameter_advice(job, 2);
  const ra::RobustCuttingAdvice robust = ra::robust_cutting_advice(job, nominal.advice, 2);
  ASSERT_TRUE(robust.advice.feasible);
  ASSERT_TRUE(nominal.advice.feasible);
  EXPECT_DOUBLE_EQ(robust.max_chatter_probability, 0.05) << "the default";

  const double speed = robust.advice.best.spindle_rad_s;
  const double depth = robust.advice.best.depth_m;
  const std::vector<robomill::dynamics::ModalModel> stations = ra::advice_stations(job, {});
  const robomill::stability::RegenerativeModel model(robomill::tool::Tool(*job.tool), *job.cutting,
                                                     *job.process, stations.front());
  const double a_nominal =
      rp::limit_curve(model, {speed}, job.advise->limit, 1).front().depth_limit_m;
  auto fraction_chattering = [&](double limit, double d) {
    int count = 0;
    for (int i = 0; i < robust.draw_count; ++i)
      count += limit / robust.draws.values(i, 0) < d ? 1 : 0;
    return static_cast<double>(count) / robust.draw_count;
  };
  EXPECT_EQ(robust.p_chatter.value, fraction_chattering(a_nominal, depth));
  EXPECT_LE(robust.p_chatter.value, 0.05);
  EXPECT_NEAR(robust.p_chatter.standard_error,
              std::sqrt(robust.p_chatter.value * (1.0 - robust.p_chatter.value) / 200.0), 1e-15);
  EXPECT_GT(fraction_chattering(a_nominal, depth + 0.037e-3), 0.05)
      << "one step deeper breaks the bound";
  EXPECT_FALSE(robust.advice.best.offset_limited);

  const double nominal_p =
      fraction_chattering(nominal.advice.best.limit_depth_m, nominal.advice.best.depth_m);
  EXPECT_EQ(robust.nominal_p_chatter.value, nominal_p);
  EXPECT_GT(nominal_p, 0.3);
  EXPECT_LT(nominal_p, 0.6);
  EXPECT_LT(robust.advice.best.mrr_m3_per_s, nominal.advice.best.mrr_m3_per_s)
      << "the robust advice gives up material removal for safety";
}

// A vanishing spread (σ = 1e-9) gives the nominal advice back: the same
// speed and the same depth step, every scanned limit within 1e-6.
TEST(RobustAdvice, TinySpreadGivesTheNominalAdvice) {
  const job::Job job = parse(advice_yaml("", common_factor(40, "1e-9")));
  const ra::CuttingParameterAdvice nominal = ra::cutting_parameter_advice(job, 2);
  const ra::RobustCuttingAdvice robust = ra::robust_cutting_advice(job, nominal.advice, 2);
  EXPECT_EQ(robust.advice.best.spindle_rad_s, nominal.advice.best.spindle_rad_s);
  EXPECT_EQ(robust.advice.best.depth_m, nominal.advice.best.depth_m);
  const std::vector<rp::SpeedAdvice> a = scanned(nominal.advice);
  const std::vector<rp::SpeedAdvice> r = scanned(robust.advice);
  ASSERT_EQ(a.size(), r.size());
  for (std::size_t k = 0; k < a.size(); ++k)
    EXPECT_NEAR(r[k].limit_depth_m, a[k].limit_depth_m, 1e-6 * a[k].limit_depth_m);
  EXPECT_EQ(robust.p_chatter.value, 0.0);
}

// One thread or three: the same advice, to the bit.
TEST(RobustAdvice, ThreadCountDoesNotChangeTheAdvice) {
  const job::Job job =
      parse(advice_yaml("  max_chatter_probability: 0.1\n", common_factor(60, "0.3")));
  const ra::CuttingParameterAdvice nominal = ra::cutting_parameter_advice(job, 1);
  const ra::RobustCuttingAdvice one = ra::robust_cutting_advice(job, nominal.advice, 1);
  const ra::RobustCuttingAdvice three = ra::robust_cutting_advice(job, nominal.advice, 3);
  EXPECT_EQ(one.advice.best.spindle_rad_s, three.advice.best.spindle_rad_s);
  EXPECT_EQ(one.advice.best.depth_m, three.advice.best.depth_m);
  ASSERT_EQ(one.advice.scan.size(), three.advice.scan.size());
  for (std::size_t k = 0; k < one.advice.scan.size(); ++k)
    EXPECT_EQ(one.advice.scan[k].limit_depth_m, three.advice.scan[k].limit_depth_m);
  EXPECT_EQ(one.p_chatter.value, three.p_chatter.value);
}

// Without an uncertainty: section there is nothing to be robust against;
// a probability bound outside (0, 1) is refused by the job reader.
TEST(RobustAdvice, NeedsAnUncertaintySectionAndAProbability) {
  const job::Job job = parse(advice_yaml("", ""));
  const ra::CuttingParameterAdvice nominal = ra::cutting_parameter_advice(job, 1);
  try {
    (void)ra::robust_cutting_advice(job, nominal.advice, 1);
    FAIL() << "no uncertainty section accepted";
  } catch (const robomill::InputError& e) {
    EXPECT_EQ(e.field(), "uncertainty");
  }
  for (const char* bad : {"0", "1", "150 %", "-0.05"}) {
    try {
      (void)parse(advice_yaml(std::string("  max_chatter_probability: ") + bad + "\n",
                              common_factor(10, "0.1")));
      FAIL() << "max_chatter_probability " << bad << " accepted";
    } catch (const robomill::InputError& e) {
      EXPECT_EQ(e.field(), "advise.max_chatter_probability") << bad;
      EXPECT_GT(e.line(), 0) << bad;
    }
  }
}

}  // namespace test_robust_advice_cpp
