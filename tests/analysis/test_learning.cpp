// analysis::learn (issue 35): the fast model against the stability diagram,
// its refusals, and the anchor's numerical case learned from tests the
// learning chooses itself, labelled by a semi-discretization of a truth drawn
// from the prior (its values are whatever the seed gives: nobody chose them).

#include "robomill/analysis/learning.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "robomill/analysis/learning_model.hpp"
#include "robomill/analysis/stability_diagram.hpp"
#include "robomill/analysis/structure.hpp"
#include "robomill/core/constants.hpp"
#include "robomill/core/error.hpp"
#include "robomill/dynamics/frf.hpp"
#include "robomill/job/job.hpp"
#include "robomill/planning/workpiece_placement.hpp"
#include "robomill/robot/kinematics.hpp"
#include "robomill/robot/robot_model.hpp"
#include "robomill/uncertainty/draws.hpp"
#include "support/anchor_cut.hpp"

namespace test_learning_cpp {

namespace ra = robomill::analysis;
namespace job = robomill::job;
namespace uq = robomill::uncertainty;

namespace {

/// The anchor's case (examples/learn/anchor_tool.yaml) on a coarser grid: 41
/// speeds × 40 depths, 1000 samples.
std::string anchor_yaml(const std::string& method, const std::string& experiments) {
  return R"(name: learning test
tool: {type: flat, diameter: 12.7 mm, teeth: 3, helix: 0 deg, overhang: 40 mm}
cutting: {law: linear, Ktc: 556 N/mm^2, Krc: 225 N/mm^2}
process: {spindle: 8000 rpm, feed_per_tooth: 0.1 mm, ap: 2 mm, ae: 6.35 mm, direction: down}
dynamics:
  modes:
    - {direction: x, fn: 1500 Hz, zeta: 0.03, k: 1.0e7 N/m}
    - {direction: y, fn: 1500 Hz, zeta: 0.03, k: 1.0e7 N/m}
stability:
  method: )" +
         method + R"(
  speeds: {from: 4000 rpm, to: 12000 rpm, count: 41}
  depth_max: 8 mm
  depths: 40
  discretization: 40
uncertainty:
  samples: 500
  seed: 35
  variables:
    - {name: Ktc, path: cutting.Ktc, distribution: truncated_normal, mean: 556, sd: 115, min: 0}
    - {name: Krc, path: cutting.Krc, distribution: truncated_normal, mean: 225, sd: 80, min: 0}
    - {name: fn, path: [dynamics.modes.0.fn, dynamics.modes.1.fn], distribution: truncated_normal, mean: 1500, sd: 150, min: 0}
    - {name: k, path: [dynamics.modes.0.k, dynamics.modes.1.k], distribution: truncated_normal, mean: 1.0e7, sd: 2.0e6, min: 0}
    - {name: zeta, path: [dynamics.modes.0.zeta, dynamics.modes.1.zeta], distribution: truncated_normal, mean: 0.03, sd: 0.009, min: 0}
  correlation: {Ktc: {Krc: 0.35}}
learn: {samples: 1000, seed: 7}
)" + experiments;
}

/// Checks the model's `limits` against the diagram's at its speeds (limited
/// alike: the model searches to 1.25 × depth_max, search_depth_m, the
/// diagram to depth_max; each limit within `relative`); the number of
/// speeds limited in the diagram.
int expect_the_diagrams_limits(const std::vector<robomill::stability::ZeroOrderLimit>& limits,
                               const ra::StabilityDiagram& diagram, double depth_max_m,
                               double relative) {
  int limited = 0;
  for (std::size_t s = 0; s < limits.size(); ++s) {
    const auto& reference = diagram.primary()[s];
    EXPECT_EQ(limits[s].limited && limits[s].depth_limit_m <= depth_max_m, reference.limited) << s;
    if (!reference.limited)
      continue;
    ++limited;
    EXPECT_NEAR(limits[s].depth_limit_m, reference.depth_limit_m,
                relative * reference.depth_limit_m)
        << s;
  }
  return limited;
}

TEST(LearningModel, ItsLimitsAreTheStabilityDiagramsOnTheNominalJob) {
  const job::Job j = job::parse_job(anchor_yaml("zoa", ""), "anchor.yaml");
  const ra::LearningModel model(j);
  const ra::StabilityDiagram diagram = ra::stability_diagram(j, 1);
  std::vector<robomill::stability::ZeroOrderLimit> limits(diagram.speeds_rad_s.size());
  ASSERT_TRUE(model.limits(model.nominal_values(), diagram.speeds_rad_s, limits));
  int limited = 0;
  for (std::size_t s = 0; s < limits.size(); ++s) {
    const auto& reference = diagram.primary()[s];
    ASSERT_EQ(limits[s].limited, reference.limited) << s;
    if (!reference.limited)
      continue;
    ++limited;
    // The coarser grid finds the same crossing; both are refined on the
    // exact eigenvalues.
    EXPECT_NEAR(limits[s].depth_limit_m, reference.depth_limit_m, 1e-9 * reference.depth_limit_m)
        << s;
    EXPECT_NEAR(limits[s].chatter_frequency_hz, reference.chatter_frequency_hz, 1e-6) << s;
  }
  EXPECT_GT(limited, 30);
}

/// learn.method: sdm puts the probit around the semi-discretization's
/// limit: the model's limits are the SDM diagram's on the nominal job (the
/// model searches to 10 mm, the diagram to 8: the coarse scans differ, so
/// the limits agree to the bracket's tolerance, 1e-3 relative, each way).
TEST(LearningModel, WithATimeDomainMethodItsLimitsAreThatMethodsDiagram) {
  const job::Job j = job::parse_job(anchor_yaml("sdm", ""), "anchor.yaml",
                                    {{"learn.method", "sdm"}, {"stability.speeds.count", "13"}});
  const ra::LearningModel model(j);
  const ra::StabilityDiagram diagram = ra::stability_diagram(j, 1);
  std::vector<robomill::stability::ZeroOrderLimit> limits(diagram.speeds_rad_s.size());
  ASSERT_TRUE(model.limits(model.nominal_values(), diagram.speeds_rad_s, limits));
  EXPECT_GE(expect_the_diagrams_limits(limits, diagram, j.stability->depth_max_m, 2e-3), 10);
}

/// A test of another radial depth and direction (experiments[].ae,
/// direction) is predicted with its own cut: the model's limits for it are
/// the diagram of the job whose process has that cut.
TEST(LearningModel, ATestOfAnotherCutHasThatCutsDiagram) {
  const job::Job j = job::parse_job(
      anchor_yaml("zoa",
                  "experiments:\n  - {spindle: 7123 rpm, depth: 1.37 mm, chatter: false, ae: "
                  "2.17 mm, direction: up}\n"),
      "anchor.yaml");
  const ra::LearningModel model(j);
  const int cut = model.cut_of(j.experiments[0]);
  EXPECT_EQ(cut, 1);
  const job::Job other = job::parse_job(anchor_yaml("zoa", ""), "anchor.yaml",
                                        {{"process.ae", "2.17 mm"}, {"process.direction", "up"}});
  const ra::StabilityDiagram diagram = ra::stability_diagram(other, 1);
  std::vector<robomill::stability::ZeroOrderLimit> limits(diagram.speeds_rad_s.size());
  ASSERT_TRUE(model.limits(model.nominal_values(), 0, cut, diagram.speeds_rad_s, limits));
  std::vector<robomill::stability::ZeroOrderLimit> own(diagram.speeds_rad_s.size());
  ASSERT_TRUE(model.limits(model.nominal_values(), 0, 0, diagram.speeds_rad_s, own));
  const int limited =
      expect_the_diagrams_limits(limits, diagram, other.stability->depth_max_m, 1e-9);
  int differ = 0;
  for (std::size_t s = 0; s < limits.size(); ++s) {
    differ +=
        diagram.primary()[s].limited && own[s].limited &&
        std::abs(own[s].depth_limit_m - limits[s].depth_limit_m) > 0.05 * limits[s].depth_limit_m;
  }
  // A sixth-immersion up-milling cut is stable beyond 8 mm at most speeds.
  EXPECT_GE(limited, 10);
  EXPECT_EQ(differ, limited);  // the job's own cut (50 % down) is another diagram
}

TEST(LearningModel, RefusesWhatItCannotSetDirectly) {
  // A variable on the radial immersion: not a coefficient or a mode.
  std::string text = anchor_yaml("zoa", "");
  const std::string ktc =
      "{name: Ktc, path: cutting.Ktc, distribution: truncated_normal, mean: 556, sd: 115, min: 0}";
  std::string ae = text;
  ae.replace(ae.find(ktc), ktc.size(),
             "{name: Ktc, path: process.ae, distribution: uniform, min: 5, max: 7}");
  try {
    const ra::LearningModel model(job::parse_job(ae, "ae.yaml"));
    ADD_FAILURE() << "accepted";
  } catch (const robomill::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("process.ae"), std::string::npos) << e.what();
    EXPECT_NE(e.field().find("uncertainty.variables[0]"), std::string::npos) << e.field();
  }
  // A mode given by its mass: k follows fn when the job is re-read.
  std::string mass = text;
  const std::string mode_x = "{direction: x, fn: 1500 Hz, zeta: 0.03, k: 1.0e7 N/m}";
  mass.replace(mass.find(mode_x), mode_x.size(),
               "{direction: x, fn: 1500 Hz, zeta: 0.03, m: 0.11258 kg}");
  EXPECT_THROW(ra::LearningModel(job::parse_job(mass, "mass.yaml")), robomill::InputError);
  // No uncertainty section.
  const std::string no_prior = text.substr(0, text.find("uncertainty:"));
  EXPECT_THROW(ra::LearningModel(job::parse_job(no_prior, "none.yaml")), robomill::InputError);
}

TEST(Learning, ContradictoryTestsGiveAProperPosteriorAndAWarningNamingBoth) {
  const std::string experiments = R"(experiments:
  - {spindle: 7340 rpm, depth: 5 mm, chatter: false}
  - {spindle: 7340 rpm, depth: 1 mm, chatter: true}
)";
  // 400 samples: the checks are on the warning and the posterior's being proper.
  const ra::LearningResult r = ra::learn(
      job::parse_job(anchor_yaml("zoa", experiments), "c.yaml", {{"learn.samples", "400"}}));
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("experiments[0]"), std::string::npos) << r.warnings[0];
  EXPECT_NE(r.warnings[0].find("experiments[1]"), std::string::npos) << r.warnings[0];
  EXPECT_TRUE(std::isfinite(r.sampler.log_evidence));
  EXPECT_EQ(r.posterior_values.rows(), 400);
  // A chatter at 0.05 mm: no value the prior allows predicts it (the
  // lowest limits are some 0.5 mm): a warning naming the test.
  const std::string beyond = R"(experiments:
  - {spindle: 9130 rpm, depth: 0.05 mm, chatter: true}
)";
  const ra::LearningResult b =
      ra::learn(job::parse_job(anchor_yaml("zoa", beyond), "b.yaml", {{"learn.samples", "200"}}));
  ASSERT_EQ(b.warnings.size(), 1u);
  EXPECT_NE(b.warnings[0].find("experiments[0]"), std::string::npos) << b.warnings[0];
  EXPECT_NE(b.warnings[0].find("can hardly reach"), std::string::npos) << b.warnings[0];
  EXPECT_TRUE(r.posterior_values.allFinite());
}

/// The one-DOF benchmark's recorded pair (examples/listen) as experiments:
/// the verdicts, chatter line and spindle speed come from `listen`'s
/// analysis; a recording too short to judge is skipped with its reason; an
/// unreadable one is an error naming the experiment.
std::string recorded_yaml(const std::string& third) {
  return R"(name: learning from recordings
tool: {type: flat, diameter: 10 mm, teeth: 2, helix: 0 deg, overhang: 50 mm}
cutting: {law: linear, Ktc: 600 N/mm^2, Krc: 200 N/mm^2}
process: {spindle: 12000 rpm, feed_per_tooth: 0.1 mm, ap: 1 mm, ae: 0.5 mm, direction: down}
dynamics:
  modes:
    - {direction: x, fn: 922 Hz, zeta: 0.011, k: 1.34e6 N/m}
stability: {method: zoa, speeds: {from: 8000 rpm, to: 16000 rpm, count: 41}, depth_max: 10 mm, depths: 20}
uncertainty:
  variables:
    - {name: k, path: dynamics.modes.0.k, mode: scale, distribution: lognormal, median: 1, sigma: 0.3}
    - {name: zeta, path: dynamics.modes.0.zeta, mode: scale, distribution: lognormal, median: 1, sigma: 0.3}
learn: {samples: 300}
experiments:
  - spindle: 12000 rpm
    depth: 1.35056 mm
    recording: {file: displacement_stable.wav, signal: displacement, scale: 0.000295405613}
  - spindle: 12000 rpm
    depth: 2.11025 mm
    chatter: false
    recording: {file: displacement_chatter.wav, signal: displacement, scale: 0.000295405613}
  - spindle: 12000 rpm
    depth: 1.7 mm
    recording: {file: )" +
         third + R"(}
)";
}

TEST(Learning, RecordingsGiveTheVerdictsAndAnUnknownOneIsSkipped) {
  const std::filesystem::path job_file =
      std::filesystem::path(ROBOMILL_SOURCE_DIR) / "examples" / "listen" / "learning.yaml";
  const ra::LearningResult r = ra::learn(job::parse_job(
      recorded_yaml("displacement_chatter.wav, signal: displacement, duration: 0.02 s"), job_file));
  ASSERT_EQ(r.experiments.size(), 2u);
  EXPECT_TRUE(r.experiments[0].from_recording);
  EXPECT_FALSE(r.experiments[0].chatter);
  EXPECT_TRUE(r.experiments[1].chatter);  // the recording's verdict over the written one
  EXPECT_GT(r.experiments[1].chatter_frequency_hz, 0.0);
  EXPECT_NEAR(r.experiments[0].spindle_rad_s * robomill::kRpmPerRadS, 12000.0, 12.0);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("experiments[1]"), std::string::npos) << r.warnings[0];
  ASSERT_EQ(r.skipped.size(), 1u);
  EXPECT_EQ(r.skipped[0].index, 2u);
  EXPECT_NE(r.skipped[0].reason.find("unknown"), std::string::npos) << r.skipped[0].reason;
  // The posterior moved the limit at 12000 rpm between the two depths.
  const ra::StabilityBand& band = r.posterior_band;
  // 12000 rpm is the middle of the 41 speeds.
  EXPECT_NEAR(band.speeds_rad_s[20] * robomill::kRpmPerRadS, 12000.0, 1e-6);
  EXPECT_GT(band.q50_m[20].value, 1.35056e-3);
  EXPECT_LT(band.q50_m[20].value, 2.11025e-3);
  try {
    ra::learn(job::parse_job(recorded_yaml("no_such_file.wav"), job_file));
    ADD_FAILURE() << "accepted";
  } catch (const robomill::InputError& e) {
    EXPECT_EQ(e.field(), "experiments[2].recording") << e.what();
  }
}

/// Spindle power alone: Ktc and Kte with normal priors, tests whose
/// verdicts carry no information (stable at 0.3 mm, far below every prior
/// limit), powers P = a Ktc + b Kte + noise: the posterior is the
/// linear-Gaussian one in closed form (a rank-1 update along a·Ktc + b·Kte,
/// since every test has the same ratio b/a at one feed and engagement).
TEST(Learning, SpindlePowerGivesTheLinearGaussianPosterior) {
  const std::string text = "name: power\n" + robomill::test::anchor_cut_yaml() +
                           robomill::test::anchor_mode_and_coarse_grid_yaml() + R"(uncertainty:
  variables:
    - {name: Ktc, path: cutting.Ktc, distribution: normal, mean: 556, sd: 80}
    - {name: Kte, path: cutting.Kte, distribution: normal, mean: 50, sd: 10}
learn: {samples: 3000, power_sd: 6 W, seed: 3}
experiments:
  - {spindle: 5310 rpm, depth: 0.3 mm, chatter: false, power: 47.3 W}
  - {spindle: 8870 rpm, depth: 0.3 mm, chatter: false, power: 83.9 W}
  - {spindle: 11420 rpm, depth: 0.3 mm, chatter: false, power: 101.6 W}
)";
  const ra::LearningResult r = ra::learn(job::parse_job(text, "power.yaml"));
  // P = Ω R N ap/2π (fz Ktc (cos φst − cos φex) + Kte (φex − φst)); 50 % down
  // milling: φst = π/2, φex = π.
  const double speeds_rpm[3] = {5310.0, 8870.0, 11420.0}, powers[3] = {47.3, 83.9, 101.6};
  Eigen::MatrixXd a(3, 2);
  Eigen::VectorXd y(3);
  for (int i = 0; i < 3; ++i) {
    const double common = speeds_rpm[i] / robomill::kRpmPerRadS * 6.35e-3 * 3 * 0.3e-3 / (2 * M_PI);
    a(i, 0) = common * 0.1e-3 * 1.0;
    a(i, 1) = common * M_PI / 2;
    y(i) = powers[i];
  }
  const Eigen::Vector2d prior_mean(556e6, 50e3);
  const Eigen::Matrix2d prior_precision =
      Eigen::Vector2d(1 / (80e6 * 80e6), 1 / (10e3 * 10e3)).asDiagonal();
  const Eigen::Matrix2d precision = prior_precision + a.transpose() * a / 36.0;
  const Eigen::Matrix2d covariance = precision.inverse();
  const Eigen::Vector2d mean =
      covariance * (prior_precision * prior_mean + a.transpose() * y / 36.0);
  for (int j = 0; j < 2; ++j) {
    const double sd = std::sqrt(covariance(j, j));
    std::printf("%s: posterior mean %.6g (closed form %.6g), sd %.4g (%.4g)\n", j ? "Kte" : "Ktc",
                r.posterior[j].mean, mean(j), r.posterior[j].sd, sd);
    // 3000 samples: the mean within 0.1 sd, the sd within 10 %.
    EXPECT_NEAR(r.posterior[j].mean, mean(j), 0.1 * sd);
    EXPECT_NEAR(r.posterior[j].sd, sd, 0.1 * sd);
  }
  const double rho = covariance(0, 1) / std::sqrt(covariance(0, 0) * covariance(1, 1));
  EXPECT_NEAR(r.posterior_correlation(0, 1), rho, 0.1);
  ASSERT_EQ(r.experiments.size(), 3u);
  EXPECT_NEAR(r.experiments[1].predicted_power_w, 83.9, 6.0);
}

/// A truth nobody chose: one random draw of `priors` with `seed`.
Eigen::VectorXd random_truth(const std::vector<uq::Distribution>& priors, std::uint64_t seed) {
  uq::DrawSettings draw;
  draw.samples = 1;
  draw.seed = seed;
  draw.sampling = uq::DrawSettings::Sampling::random;
  return uq::draw(priors, draw).row(0).transpose();
}

/// Writes `frf` as a CSV file (freq_hz,re,im in m/N) at `path`.
void write_frf_csv(const std::filesystem::path& path, const robomill::dynamics::Frf& frf) {
  std::FILE* f = std::fopen(path.string().c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fprintf(f, "freq_hz,re,im\n");
  for (std::size_t i = 0; i < frf.frequency_hz.size(); ++i)
    std::fprintf(f, "%.17g,%.17g,%.17g\n", frf.frequency_hz[i], frf.value[i].real(),
                 frf.value[i].imag());
  std::fclose(f);
}

/// A hammer test alone: the tool's symmetric mode (fn, k, ζ tied in x and
/// y) with log-normal priors, the truth a random draw of them (seed 11),
/// its x and y FRFs synthesized on 400-4000 Hz and fitted by learn (the
/// job's automatic bands). Each fitted mode's likelihood is log-normal
/// around the predicted mode along its axis, so with two fitted modes per
/// variable the posterior of ln fn (ln k, ln ζ) is normal in closed form:
/// precision 1/σ² + 2/s², mean (μ/σ² + (y_x + y_y)/s²)/precision, with the
/// fitted values y and the learn.frf_*_sd spreads s (2 %, 20 %, 30 %).
TEST(Learning, AHammerTestGivesTheLogNormalPosterior) {
  const std::vector<uq::Distribution> priors = {uq::Distribution(uq::Lognormal{1500.0, 0.10}),
                                                uq::Distribution(uq::Lognormal{1.0e7, 0.20}),
                                                uq::Distribution(uq::Lognormal{0.03, 0.30})};
  const Eigen::VectorXd truth = random_truth(priors, 11);
  const double omega = 2.0 * M_PI * truth(0);
  std::vector<robomill::dynamics::Mode> modes;
  for (int axis = 0; axis < 2; ++axis)
    modes.push_back(
        {truth(0), truth(2), Eigen::Vector3d::Unit(axis) * (omega / std::sqrt(truth(1)))});
  const robomill::dynamics::ModalModel structure(modes);
  std::vector<double> grid;
  for (int i = 0; i <= 1800; ++i)
    grid.push_back(400.0 + 2.0 * i);
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "robomill_test_learning_hammer";
  std::filesystem::create_directories(dir);
  write_frf_csv(dir / "x.csv", robomill::dynamics::synthesize(structure, 0, 0, grid));
  write_frf_csv(dir / "y.csv", robomill::dynamics::synthesize(structure, 1, 1, grid));
  const std::string text = "name: hammer\n" + robomill::test::anchor_cut_yaml() +
                           robomill::test::anchor_mode_and_coarse_grid_yaml() + R"(uncertainty:
  variables:
    - {name: fn, path: [dynamics.modes.0.fn, dynamics.modes.1.fn], distribution: lognormal, median: 1500, sigma: 0.10}
    - {name: k, path: [dynamics.modes.0.k, dynamics.modes.1.k], distribution: lognormal, median: 1.0e7, sigma: 0.20}
    - {name: zeta, path: [dynamics.modes.0.zeta, dynamics.modes.1.zeta], distribution: lognormal, median: 0.03, sigma: 0.30}
learn: {samples: 3000, seed: 5}
experiments:
  - frf: {x: {file: x.csv, units: m/N}, y: {file: y.csv, units: m/N}}
)";
  const ra::LearningResult r = ra::learn(job::parse_job(text, dir / "hammer.yaml"));
  ASSERT_EQ(r.hammer_modes.size(), 2u);
  ASSERT_TRUE(r.experiments.empty());
  const double prior_sigma[3] = {0.10, 0.20, 0.30}, spread[3] = {0.02, 0.20, 0.30};
  const double prior_median[3] = {1500.0, 1.0e7, 0.03};
  for (int j = 0; j < 3; ++j) {
    double fitted[2];
    for (int m = 0; m < 2; ++m) {
      const ra::LearnedHammerMode& h = r.hammer_modes[static_cast<std::size_t>(m)];
      EXPECT_EQ(h.axis, m);
      fitted[m] = j == 0 ? h.fn_hz : j == 1 ? h.k_n_per_m : h.zeta;
    }
    // The fit of a noise-free FRF returns the truth.
    EXPECT_NEAR(fitted[0], truth(j), 1e-3 * truth(j)) << r.names[static_cast<std::size_t>(j)];
    const double precision =
        1.0 / (prior_sigma[j] * prior_sigma[j]) + 2.0 / (spread[j] * spread[j]);
    const double mean = (std::log(prior_median[j]) / (prior_sigma[j] * prior_sigma[j]) +
                         (std::log(fitted[0]) + std::log(fitted[1])) / (spread[j] * spread[j])) /
                        precision;
    const double sd = 1.0 / std::sqrt(precision);
    const Eigen::ArrayXd logs = r.posterior_values.col(j).array().log();
    const double sample_mean = logs.mean();
    const double sample_sd = std::sqrt((logs - sample_mean).square().sum() / (logs.size() - 1));
    std::printf(
        "%s: truth %.6g, fitted %.6g/%.6g; posterior ln mean %.6f (closed form %.6f), "
        "sd %.5f (%.5f)\n",
        r.names[static_cast<std::size_t>(j)].c_str(), truth(j), fitted[0], fitted[1], sample_mean,
        mean, sample_sd, sd);
    // 3000 samples: the mean within 0.1 sd, the sd within 10 %.
    EXPECT_NEAR(sample_mean, mean, 0.1 * sd);
    EXPECT_NEAR(sample_sd, sd, 0.1 * sd);
  }
  // A hammer test on a robot needs its posture.
  const std::filesystem::path robot_file =
      std::filesystem::path(ROBOMILL_SOURCE_DIR) / "examples" / "learn" / "kr270_robot.yaml";
  const job::Job robot_job = job::load_job(
      robot_file, {{"experiments", fmt::format("[{{frf: {{x: {{file: {}, units: m/N}}}}}}]",
                                               (dir / "x.csv").string())}});
  try {
    ra::learn(robot_job);
    ADD_FAILURE() << "accepted";
  } catch (const robomill::InputError& e) {
    EXPECT_EQ(e.field(), "experiments[0].posture") << e.what();
    EXPECT_NE(std::string(e.what()).find("hammer test"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

/// The overrides that make the KR 270 learn examples' job the truth at a
/// posture (deg): the joint stiffnesses × the factors truth(0) (joints 1-3)
/// and truth(1) (4-6), the damping ratio 2 % × truth(2), no experiments.
std::vector<job::Override> robot_truth_at(const job::Job& robot_job, const Eigen::VectorXd& truth,
                                          const std::vector<double>& posture_rad) {
  std::vector<job::Override> truth_at;
  for (int j = 0; j < 6; ++j)
    truth_at.push_back(
        {fmt::format("robot.joint_stiffness.{}", j),
         fmt::format("{:.17g}", robot_job.robot->description.joints[j].stiffness_nm_per_rad *
                                    truth(j < 3 ? 0 : 1))});
  truth_at.push_back({"robot.damping_ratio", fmt::format("{:.17g}", 0.02 * truth(2))});
  std::string posture = "[";
  for (std::size_t j = 0; j < posture_rad.size(); ++j)
    posture += fmt::format("{}{:.17g}", j ? ", " : "", posture_rad[j] * 180.0 / M_PI);
  truth_at.push_back({"robot.posture", posture + "]"});
  truth_at.push_back({"experiments", "[]"});
  return truth_at;
}

/// The examples' KR 270 (examples/learn/kr270_robot.yaml) with hammer
/// tests instead of cuts: the truth a random draw of the prior (seed 13);
/// one test at a posture without a cut (the first of learn.places), one at
/// a position of a part on a table (its posture by inverse kinematics, the
/// tool along the part's z), each the truth's x and y tool-tip FRFs
/// synthesized at that posture (0.5-150 Hz) and fitted by learn. The
/// posterior medians of the two stiffness factors must lie within 3 % of
/// the truth and their spreads be under a fifth of the prior's; the posture found
/// for the position must put the tool tip there.
TEST(Learning, ARobotsHammerTestsAtAPostureAndAPositionTeachItsStiffness) {
  const std::filesystem::path file =
      std::filesystem::path(ROBOMILL_SOURCE_DIR) / "examples" / "learn" / "kr270_robot.yaml";
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "robomill_test_learning_robot_hammer";
  std::filesystem::create_directories(dir);
  const std::string experiments = fmt::format(
      "[{{posture: [13.7, 31.2, 8.4, 0, 52.6, 0], frf: {{x: {{file: {0}/a_x.csv, units: m/N}}, "
      "y: {{file: {0}/a_y.csv, units: m/N}}}}}}, {{position: [312.5, 287.0, 104.0], frf: {{x: "
      "{{file: {0}/b_x.csv, units: m/N}}, y: {{file: {0}/b_y.csv, units: m/N}}}}}}]",
      dir.string());
  const std::vector<job::Override> overrides = {{"experiments", experiments},
                                                {"workpiece", "{table: [1500, -300, 500]}"},
                                                {"workpiece.pose", "{x: 0, y: 0, theta: 3}"},
                                                {"learn.samples", "1000"}};
  const job::Job robot_job = job::load_job(file, overrides);
  const ra::LearningModel model(robot_job);
  // The position's posture puts the tip at the table + pose + position.
  const robomill::robot::RobotModel robot(robot_job.robot->description);
  const std::vector<double>& found = model.experiment_posture(1);
  ASSERT_EQ(found.size(), 6u);
  const Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(found.data(), 6);
  const Eigen::Isometry3d to_cell =
      robomill::planning::workpiece_to_cell(robot_job.workpiece->cell, *robot_job.workpiece->pose);
  const Eigen::Vector3d tip = robomill::robot::tool_pose(robot, q).translation();
  EXPECT_LT((tip - to_cell * Eigen::Vector3d(0.3125, 0.287, 0.104)).norm(), 1e-6);
  EXPECT_GT(robomill::robot::tool_pose(robot, q).linear().col(2).dot(to_cell.linear().col(2)),
            1.0 - 1e-9);

  const Eigen::VectorXd truth = random_truth(model.priors(), 13);
  std::vector<double> grid;
  for (int i = 0; i < 1500; ++i)
    grid.push_back(0.5 + 0.1 * i);
  const char* names[2] = {"a", "b"};
  for (std::size_t t = 0; t < 2; ++t) {
    const robomill::dynamics::ModalModel modes = ra::structure_modes(
        job::load_job(file, robot_truth_at(robot_job, truth, model.experiment_posture(t))));
    for (int axis = 0; axis < 2; ++axis)
      write_frf_csv(dir / fmt::format("{}_{}.csv", names[t], axis == 0 ? "x" : "y"),
                    robomill::dynamics::synthesize(modes, axis, axis, grid));
  }
  const ra::LearningResult r = ra::learn(robot_job);
  EXPECT_TRUE(r.experiments.empty());
  ASSERT_FALSE(r.hammer_modes.empty());
  for (const ra::LearnedHammerMode& m : r.hammer_modes)
    std::printf(
        "test %zu axis %d: fitted %.3f Hz, k %.4g N/m, zeta %.4f; nearest predicted "
        "%.3f Hz, %.4g N/m (prior), %.3f Hz, %.4g N/m (posterior)\n",
        m.index, m.axis, m.fn_hz, m.k_n_per_m, m.zeta, m.prior_fn_hz, m.prior_k_n_per_m,
        m.posterior_fn_hz, m.posterior_k_n_per_m);
  for (int j = 0; j < 3; ++j)
    std::printf("%s: truth %.4f, posterior median %.4f (5-95 %% %.4f-%.4f), sd %.4f (prior %.4f)\n",
                r.names[static_cast<std::size_t>(j)].c_str(), truth(j), r.posterior[j].q50,
                r.posterior[j].q05, r.posterior[j].q95, r.posterior[j].sd, r.prior[j].sd);
  for (int j = 0; j < 2; ++j) {
    EXPECT_NEAR(r.posterior[j].q50, truth(j), 0.03 * truth(j))
        << r.names[static_cast<std::size_t>(j)];
    EXPECT_LT(r.posterior[j].sd, 0.2 * r.prior[j].sd) << r.names[static_cast<std::size_t>(j)];
  }
  std::filesystem::remove_all(dir);
}

/// The hammer example (examples/learn/kr270_hammer.yaml): FRFs of the same
/// hidden truth as the cuts of kr270_robot.yaml (the prior drawn at random,
/// seed 7) with 2 % complex noise, at a posture and at a position. Every
/// variable's truth must lie inside its posterior 5-95 % range, and the
/// stiffness factors' spreads be under a fifth of the prior's.
TEST(Learning, TheHammerExampleFindsItsHiddenTruth) {
  const std::filesystem::path file =
      std::filesystem::path(ROBOMILL_SOURCE_DIR) / "examples" / "learn" / "kr270_hammer.yaml";
  const job::Job j = job::load_job(file, {{"learn.samples", "1000"}});
  const Eigen::VectorXd truth = random_truth(ra::LearningModel(j).priors(), 7);
  const ra::LearningResult r = ra::learn(j);
  EXPECT_EQ(r.hammer_modes.size(), 8u);
  for (int v = 0; v < 3; ++v) {
    const ra::VariableSummary& p = r.posterior[static_cast<std::size_t>(v)];
    std::printf("%s: truth %.4f, posterior 5-95 %% %.4f-%.4f, sd %.4f (prior %.4f)\n",
                r.names[static_cast<std::size_t>(v)].c_str(), truth(v), p.q05, p.q95, p.sd,
                r.prior[static_cast<std::size_t>(v)].sd);
    EXPECT_GE(truth(v), p.q05) << r.names[static_cast<std::size_t>(v)];
    EXPECT_LE(truth(v), p.q95) << r.names[static_cast<std::size_t>(v)];
    if (v < 2) {
      EXPECT_LT(p.sd, 0.2 * r.prior[static_cast<std::size_t>(v)].sd);
    }
  }
}

/// The examples' KR 270 (examples/learn/kr270_robot.yaml): its main-axis
/// and wrist joint stiffness factors and its damping factor drawn from the
/// prior (random points, seed 7: the truth its nine tests were labelled by,
/// not written in the example), learned from the tests at three postures;
/// at the two postures without a test (learn.places) the truth's limit, the
/// job re-read with the true values at that posture, must lie inside the
/// posterior's 5-95 % band at ≥ 85 % of the speeds, and the posterior
/// median's mean error be at most half the prior median's (issue 35).
TEST(Learning, ARobotLearnedAtThreePosturesPredictsTwoOthers) {
  const std::filesystem::path file =
      std::filesystem::path(ROBOMILL_SOURCE_DIR) / "examples" / "learn" / "kr270_robot.yaml";
  const job::Job robot_job = job::load_job(file, {{"learn.samples", "1000"}});
  const std::vector<uq::Distribution> priors = {uq::Distribution(uq::Lognormal{1.0, 0.25}),
                                                uq::Distribution(uq::Lognormal{1.0, 0.25}),
                                                uq::Distribution(uq::Lognormal{1.0, 0.35})};
  const Eigen::VectorXd truth = random_truth(priors, 7);
  const ra::LearningResult r = ra::learn(robot_job);
  ASSERT_EQ(r.places_rad.size(), 5u);  // robot.posture, two more tested, two predicted
  ASSERT_EQ(r.more_places.size(), 4u);
  for (std::size_t p = 2; p < 4; ++p) {
    const ra::PlaceBands& at = r.more_places[p];
    const ra::StabilityDiagram diagram = ra::stability_diagram(
        job::load_job(file, robot_truth_at(robot_job, truth, at.posture_rad)), 0);
    int inside = 0;
    double error_posterior = 0.0, error_prior = 0.0;
    const std::size_t n = at.posterior.speeds_rad_s.size();
    ASSERT_EQ(diagram.primary().size(), n);
    for (std::size_t s = 0; s < n; ++s) {
      const double depth_max = robot_job.stability->depth_max_m;
      const auto& l = diagram.primary()[s];
      const double limit = l.limited ? std::min(l.depth_limit_m, depth_max) : depth_max;
      inside += limit >= at.posterior.q05_m[s].value - 1e-12 &&
                limit <= at.posterior.q95_m[s].value + 1e-12;
      error_posterior += std::abs(at.posterior.q50_m[s].value - limit);
      error_prior += std::abs(at.prior.q50_m[s].value - limit);
    }
    std::printf(
        "place %zu: truth inside the posterior band at %d of %zu speeds; median error "
        "%.3f mm (prior %.3f mm)\n",
        p + 1, inside, n, 1e3 * error_posterior / n, 1e3 * error_prior / n);
    EXPECT_GE(inside, static_cast<int>(std::ceil(0.85 * n))) << "place " << p + 1;
    EXPECT_LE(error_posterior, 0.5 * error_prior) << "place " << p + 1;
  }
}

/// The anchor case's hidden truth: the values of its five variables (Ktc,
/// Krc in Pa, fn in Hz, k in N/m, ζ; x and y tied) and its limits by a
/// semi-discretization at 80 steps per tooth period on the test grid (an
/// independent model of the truth: not the zero-order limit learn assumes).
class AnchorTruth {
 public:
  explicit AnchorTruth(const Eigen::VectorXd& truth) {
    const std::vector<std::string> fields = {"cutting.Ktc", "cutting.Krc", "dynamics.modes.0.fn",
                                             "dynamics.modes.0.k", "dynamics.modes.0.zeta"};
    const std::vector<std::string> units = {" Pa", " Pa", " Hz", " N/m", ""};
    std::vector<job::Override> overrides;
    for (std::size_t j = 0; j < 5; ++j) {
      const std::string value =
          fmt::format("{:.17g}", truth(static_cast<Eigen::Index>(j))) + units[j];
      overrides.push_back({fields[j], value});
      if (j >= 2) {
        std::string y = fields[j];
        y.replace(y.find(".0."), 3, ".1.");
        overrides.push_back({y, value});
      }
    }
    std::string text = anchor_yaml("sdm", "");
    text.replace(text.find("discretization: 40"), 18, "discretization: 80");
    text = text.substr(0, text.find("uncertainty:"));
    diagram_ = ra::stability_diagram(job::parse_job(text, "truth.yaml", overrides), 0);
  }
  /// The truth's limit at a grid speed (1 m when stable to depth_max).
  double limit_m(double spindle_rad_s) const {
    for (const auto& l : diagram_.primary()) {
      if (std::abs(l.spindle_rad_s - spindle_rad_s) < 1e-9 * spindle_rad_s)
        return l.limited ? l.depth_limit_m : 1.0;
    }
    ADD_FAILURE() << "not a grid speed";
    return 1.0;
  }

 private:
  ra::StabilityDiagram diagram_;
};

/// `count` tests chosen by learn one at a time on the anchor job (with
/// `overrides`), each labelled by the truth: the experiments: text.
std::string tests_chosen_by_learn(const AnchorTruth& truth, int count,
                                  const std::vector<job::Override>& overrides) {
  std::string experiments = "experiments:\n";
  for (int tests = 0; tests < count; ++tests) {
    const ra::LearningResult r = ra::learn(
        job::parse_job(anchor_yaml("zoa", tests ? experiments : ""), "loop.yaml", overrides));
    EXPECT_TRUE(r.next.found) << r.next.reason;
    if (!r.next.found)
      break;
    const bool chatter = r.next.depth_m > truth.limit_m(r.next.spindle_rad_s);
    experiments += fmt::format("  - {{spindle: {:.17g} rpm, depth: {:.17g} mm, chatter: {}}}\n",
                               r.next.spindle_rad_s * robomill::kRpmPerRadS, r.next.depth_m * 1e3,
                               chatter ? "true" : "false");
  }
  return experiments;
}

/// The anchor's judging loop on a coarser grid: tests chosen by learn one at a
/// time (switching strategy), each labelled by the truth's semi-discretization
/// limit at that speed (80 steps per tooth period), 15 tests. Then the
/// posterior mean fn must lie within 3 % of the truth's and the posterior
/// P(chatter) map classify ≥ 95 % of the 41 × 40 grid as the truth does
/// (issue 35's criteria, on a coarser grid and 1000 samples).
TEST(Learning, TheAnchorCaseLearnsAHiddenTruthFromTheTestsItChooses) {
  const job::Job prior_job = job::parse_job(anchor_yaml("zoa", ""), "anchor.yaml");
  const ra::LearningModel model(prior_job);
  // The truth: a draw of the prior (seed 2026, the first Sobol point after
  // the centre), not a value anyone picked.
  std::vector<uq::Distribution> priors = model.priors();
  uq::DrawSettings draw;
  draw.samples = 2;
  draw.seed = 2026;
  draw.correlation = prior_job.uncertainty->correlation;
  const Eigen::VectorXd truth = uq::draw(priors, draw).row(1).transpose();
  const AnchorTruth labels(truth);
  const auto truth_limit = [&](double spindle_rad_s) { return labels.limit_m(spindle_rad_s); };
  const std::string experiments = tests_chosen_by_learn(labels, 15, {});
  const int tests = 15;
  const ra::LearningResult r =
      ra::learn(job::parse_job(anchor_yaml("zoa", experiments), "final.yaml"));
  const double fn_error = r.posterior[2].mean / truth(2) - 1.0;
  int agree = 0, cells = 0;
  for (std::size_t s = 0; s < r.posterior_band.speeds_rad_s.size(); ++s) {
    const double limit = truth_limit(r.posterior_band.speeds_rad_s[s]);
    for (std::size_t d = 0; d < r.posterior_band.depths_m.size(); ++d, ++cells) {
      const bool predicted = r.posterior_band.p_chatter(static_cast<Eigen::Index>(d),
                                                        static_cast<Eigen::Index>(s)) > 0.5;
      agree += predicted == (r.posterior_band.depths_m[d] > limit);
    }
  }
  const double agreement = static_cast<double>(agree) / cells;
  std::printf(
      "anchor loop: truth Ktc %.4g Pa, Krc %.4g Pa, fn %.2f Hz, k %.4g N/m, zeta %.4f; "
      "%d tests; posterior fn %.2f Hz (%+.2f %%), agreement %.3f\n",
      truth(0), truth(1), truth(2), truth(3), truth(4), tests, r.posterior[2].mean,
      100.0 * fn_error, agreement);
  EXPECT_LT(std::abs(fn_error), 0.03);
  EXPECT_GE(agreement, 0.95);
}

/// Calibration (issue 35): over 20 worlds drawn from the prior (random
/// draws, seeds 101-120, the prior's correlation), each learned from 6
/// tests it chose (500 samples, labels by each truth's semi-discretization
/// at 80 steps), the posterior 5-95 % band must hold the truth's limit
/// (capped at depth_max, as the band is) at 80-97 % of the world-speeds. A
/// smaller run than docs/learning.md's study (8 tests, 1000 samples): the
/// same loop, in CI.
TEST(Learning, PosteriorBandsAreCalibratedOverWorldsDrawnFromThePrior) {
  const job::Job prior_job = job::parse_job(anchor_yaml("zoa", ""), "anchor.yaml");
  const ra::LearningModel model(prior_job);
  const std::vector<job::Override> overrides = {{"learn.samples", "500"},
                                                {"uncertainty.samples", "100"}};
  int inside = 0, total = 0;
  for (std::uint64_t seed = 101; seed <= 120; ++seed) {
    uq::DrawSettings draw;
    draw.samples = 1;
    draw.seed = seed;
    draw.sampling = uq::DrawSettings::Sampling::random;
    draw.correlation = prior_job.uncertainty->correlation;
    const Eigen::VectorXd truth = uq::draw(model.priors(), draw).row(0).transpose();
    const AnchorTruth labels(truth);
    const std::string experiments = tests_chosen_by_learn(labels, 6, overrides);
    const ra::LearningResult r =
        ra::learn(job::parse_job(anchor_yaml("zoa", experiments), "world.yaml", overrides));
    const ra::StabilityBand& band = r.posterior_band;
    int in_world = 0;
    for (std::size_t s = 0; s < band.speeds_rad_s.size(); ++s) {
      const double limit =
          std::min(labels.limit_m(band.speeds_rad_s[s]), prior_job.stability->depth_max_m);
      in_world += limit >= band.q05_m[s].value - 1e-12 && limit <= band.q95_m[s].value + 1e-12;
    }
    std::printf("world %llu (fn %.0f Hz, zeta %.4f): truth inside the band at %d of %zu speeds\n",
                static_cast<unsigned long long>(seed), truth(2), truth(4), in_world,
                band.speeds_rad_s.size());
    inside += in_world;
    total += static_cast<int>(band.speeds_rad_s.size());
  }
  const double coverage = static_cast<double>(inside) / total;
  std::printf("calibration: %d of %d world-speeds inside the posterior 5-95 %% band: %.1f %%\n",
              inside, total, 100.0 * coverage);
  EXPECT_GE(coverage, 0.80);
  EXPECT_LE(coverage, 0.97);
}

}  // namespace
}  // namespace test_learning_cpp
