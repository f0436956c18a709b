// analysis::draw_job_inputs and job_of_draw (docs/uncertainty.md, "From a
// job"): the draws of a job's uncertainty: section follow its distributions,
// reach the job's fields exactly, are refused as a job file would be, repeat
// with the seed, and come from a posterior file when the job names one.

#include "robomill/analysis/job_draws.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "robomill/core/error.hpp"
#include "robomill/job/job.hpp"
#include "robomill/uncertainty/sample_statistics.hpp"

namespace test_job_draws_cpp {

namespace {

namespace ra = robomill::analysis;
namespace job = robomill::job;
using robomill::InputError;

// Four lines; the uncertainty: section starts on line 5.
const std::string kTwoModes = R"(dynamics:
  modes:
    - {direction: x, fn: 2060 Hz, zeta: 2.4 %, k: 8.1e6 N/m}
    - {direction: y, fn: 2150 Hz, zeta: 2.1 %, k: 9.3e6 N/m}
)";

// Same shape and every entry equal (gtest does not print Eigen matrices well).
bool same(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && (a.array() == b.array()).all();
}

job::Job two_modes(const std::string& section, const std::vector<job::Override>& set = {},
                   const std::filesystem::path& source = "job.yaml") {
  return job::parse_job(kTwoModes + section, source, set);
}

// A common lognormal factor on both modes' stiffness, and the x mode's
// damping ratio with a relative sd.
const std::string kTipAndDamping = R"(uncertainty:
  samples: 64
  variables:
    - name: k_tip
      path: ["dynamics.modes[0].k", "dynamics.modes[1].k"]
      mode: scale
      distribution: lognormal
      sigma: 0.2
    - name: zeta_x
      path: dynamics.modes[0].zeta
      distribution: normal
      sd: 10 %
)";

TEST(JobDraws, AScaleVariableDrivesEveryPathWithTheSameFactorExactly) {
  const job::Job nominal = two_modes(kTipAndDamping);
  const ra::JobDraws draws = ra::draw_job_inputs(nominal);
  EXPECT_EQ(draws.names, (std::vector<std::string>{"k_tip", "zeta_x"}));
  ASSERT_EQ(draws.values.rows(), 64);
  ASSERT_EQ(draws.values.cols(), 2);
  EXPECT_EQ(draws.source, "sobol");
  for (const std::size_t i : {0u, 17u, 63u}) {
    SCOPED_TRACE(i);
    const job::Job drawn = ra::job_of_draw(nominal, draws, i);
    const double factor = draws.values(static_cast<Eigen::Index>(i), 0);
    EXPECT_NE(factor, 1.0);
    // Written with 17 significant digits in N/m: the very product comes back.
    EXPECT_EQ(drawn.modes[0].stiffness_n_per_m, 8.1e6 * factor);
    EXPECT_EQ(drawn.modes[1].stiffness_n_per_m, 9.3e6 * factor);
    EXPECT_EQ(drawn.modes[0].damping_ratio, draws.values(static_cast<Eigen::Index>(i), 1));
    // What no variable sets stays the job's.
    EXPECT_EQ(drawn.modes[1].natural_frequency_hz, nominal.modes[1].natural_frequency_hz);
    EXPECT_EQ(drawn.modes[1].damping_ratio, nominal.modes[1].damping_ratio);
    EXPECT_FALSE(drawn.uncertainty.has_value());
  }
}

TEST(JobDraws, ARelativeNormalHasItsMeanAndSdOver4096Draws) {
  const job::Job nominal = two_modes(kTipAndDamping, {{"uncertainty.samples", "4096"}});
  const ra::JobDraws draws = ra::draw_job_inputs(nominal);
  ASSERT_EQ(draws.values.rows(), 4096);
  const Eigen::VectorXd zeta = draws.values.col(1);
  const std::span<const double> values(zeta.data(), static_cast<std::size_t>(zeta.size()));
  const double mean = 0.024, sd = 0.0024;  // the job's 2.4 %, and 10 % of it
  const double n = 4096.0;
  // Standard errors of independent draws (Sobol's are smaller): σ/√n for the
  // mean, σ/√(2(n − 1)) for the sample sd of a normal; 3 of them.
  EXPECT_NEAR(robomill::uncertainty::sample_mean(values).value, mean, 3.0 * sd / std::sqrt(n));
  EXPECT_NEAR(robomill::uncertainty::sample_standard_deviation(values), sd,
              3.0 * sd / std::sqrt(2.0 * (n - 1.0)));
}

TEST(JobDraws, AVerySmallSpreadGivesTheNominalModes) {
  // Zero spread is no distribution (sd, sigma > 0); sigma 1e-12 puts every
  // draw within ~3e-12 of the nominal value (|z| < 3 in 16 Sobol points).
  const job::Job nominal = two_modes(R"(uncertainty:
  samples: 16
  variables:
    - {name: k_tip, path: [dynamics.modes.0.k, dynamics.modes.1.k], mode: scale,
       distribution: lognormal, sigma: 1e-12}
    - {name: zeta_y, path: dynamics.modes.1.zeta, distribution: lognormal, sigma: 1e-12}
    - {name: fn_x, path: dynamics.modes.0.fn, distribution: normal, sd: 1e-12 %}
)");
  const ra::JobDraws draws = ra::draw_job_inputs(nominal);
  const auto near = [](double actual, double expected) {
    EXPECT_NEAR(actual, expected, 1e-9 * std::abs(expected));
  };
  for (std::size_t i = 0; i < 16; ++i) {
    SCOPED_TRACE(i);
    const job::Job drawn = ra::job_of_draw(nominal, draws, i);
    ASSERT_EQ(drawn.modes.size(), 2u);
    for (std::size_t m = 0; m < 2; ++m) {
      near(drawn.modes[m].stiffness_n_per_m, nominal.modes[m].stiffness_n_per_m);
      near(drawn.modes[m].mass_kg, nominal.modes[m].mass_kg);
      near(drawn.modes[m].natural_frequency_hz, nominal.modes[m].natural_frequency_hz);
      near(drawn.modes[m].damping_ratio, nominal.modes[m].damping_ratio);
    }
  }
}

TEST(JobDraws, ANegativeStiffnessDrawIsRefusedNamingTheVariable) {
  // sd 200 % of the mean: a third of the draws are negative.
  const job::Job nominal = two_modes(R"(uncertainty:
  samples: 64
  variables:
    - name: k_x
      path: dynamics.modes[0].k
      distribution: normal
      sd: 200 %
)");
  const ra::JobDraws draws = ra::draw_job_inputs(nominal);
  Eigen::Index negative = -1, positive = -1;
  for (Eigen::Index i = 0; i < draws.values.rows(); ++i)
    (draws.values(i, 0) < 0.0 ? negative : positive) = i;
  ASSERT_GE(negative, 0);
  ASSERT_GE(positive, 0);
  EXPECT_EQ(ra::job_of_draw(nominal, draws, static_cast<std::size_t>(positive))
                .modes[0]
                .stiffness_n_per_m,
            draws.values(positive, 0));
  try {
    (void)ra::job_of_draw(nominal, draws, static_cast<std::size_t>(negative));
    ADD_FAILURE() << "a negative stiffness was accepted";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_EQ(error.field(), "uncertainty.variables[0]") << message;
    EXPECT_EQ(error.line(), 8) << message;
    for (const std::string& fragment :
         {std::string("variable 'k_x'"), "draw " + std::to_string(negative),
          std::string("dynamics.modes[0].k = -"), std::string("must be positive"),
          std::string("lognormal")})
      EXPECT_NE(message.find(fragment), std::string::npos) << message << "\nlacks: " << fragment;
    EXPECT_EQ(message.find("--set"), std::string::npos) << message;
  }
}

TEST(JobDraws, TheSeedDecidesTheDrawsAndThreadsDoNot) {
  const job::Job a = two_modes(kTipAndDamping);
  const job::Job b = two_modes(kTipAndDamping);
  const ra::JobDraws first = ra::draw_job_inputs(a);
  EXPECT_TRUE(same(first.values, ra::draw_job_inputs(b).values));
  const ra::JobDraws other =
      ra::draw_job_inputs(two_modes(kTipAndDamping, {{"uncertainty.seed", "2"}}));
  EXPECT_FALSE(same(first.values, other.values));
  const ra::JobDraws random =
      ra::draw_job_inputs(two_modes(kTipAndDamping, {{"uncertainty.sampling", "random"}}));
  EXPECT_EQ(random.source, "random");
  EXPECT_FALSE(same(first.values, random.values));

  // job_of_draw from four threads at once gives the jobs it gives alone.
  std::vector<double> alone(64), together(64);
  for (std::size_t i = 0; i < 64; ++i)
    alone[i] = ra::job_of_draw(a, first, i).modes[1].stiffness_n_per_m;
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (std::size_t i = t; i < 64; i += 4)
        together[i] = ra::job_of_draw(a, first, i).modes[1].stiffness_n_per_m;
    });
  for (std::thread& thread : threads)
    thread.join();
  EXPECT_EQ(alone, together);
}

class PosteriorFile : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = std::filesystem::temp_directory_path() /
              ("robomill_test_job_draws_" + std::to_string(::getpid()));
    std::filesystem::create_directories(folder_);
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  /// The job reading `csv` as its posterior (line 6 of the job).
  job::Job job_with(const std::string& csv) {
    std::ofstream(folder_ / "posterior.csv") << csv;
    return two_modes(R"(uncertainty:
  posterior: posterior.csv
  variables:
    - {name: k_tip, path: [dynamics.modes.0.k, dynamics.modes.1.k], mode: scale}
    - {name: zeta_x, path: dynamics.modes.0.zeta, distribution: normal, sd: 10 %}
)",
                     {}, folder_ / "job.yaml");
  }

  std::string refusal(const std::string& csv) {
    const job::Job job = job_with(csv);
    try {
      (void)ra::draw_job_inputs(job);
    } catch (const InputError& error) {
      EXPECT_EQ(error.field(), "uncertainty.posterior") << error.what();
      EXPECT_EQ(error.line(), 6) << error.what();
      return error.what();
    }
    ADD_FAILURE() << "accepted:\n" << csv;
    return {};
  }

  std::filesystem::path folder_;
};

TEST_F(PosteriorFile, RowsComeBackAsTheValuesColumnsByName) {
  const job::Job nominal = job_with(
      "# draws of the learning step\n"
      "zeta_x,k_tip\n"
      "0.0231,0.93\n"
      "0.0262,1.071\n"
      "0.0207,1.0045\n");
  const ra::JobDraws draws = ra::draw_job_inputs(nominal);
  EXPECT_EQ(draws.source, (folder_ / "posterior.csv").string());
  ASSERT_EQ(draws.values.rows(), 3);
  Eigen::MatrixXd expected(3, 2);
  expected << 0.93, 0.0231, 1.071, 0.0262, 1.0045, 0.0207;
  EXPECT_TRUE(same(draws.values, expected)) << draws.values;
  const job::Job drawn = ra::job_of_draw(nominal, draws, 1);
  EXPECT_EQ(drawn.modes[1].stiffness_n_per_m, 9.3e6 * 1.071);
  EXPECT_EQ(drawn.modes[0].damping_ratio, 0.0262);
}

TEST_F(PosteriorFile, ColumnsThatDoNotMatchTheVariablesAreRefused) {
  const std::string extra = refusal("k_tip,zeta_x,k_z\n1,0.02,3\n");
  EXPECT_NE(extra.find("line 1: column 'k_z' is not a variable"), std::string::npos) << extra;
  const std::string missing = refusal("\n\nk_tip\n1.1\n");
  EXPECT_NE(missing.find("line 3: no column for variable 'zeta_x'"), std::string::npos) << missing;
  const std::string twice = refusal("k_tip,zeta_x,k_tip\n1,0.02,1\n");
  EXPECT_NE(twice.find("column 'k_tip' is given twice"), std::string::npos) << twice;
  const std::string empty = refusal("k_tip,zeta_x\n");
  EXPECT_NE(empty.find("no draws"), std::string::npos) << empty;
  const std::string ragged = refusal("k_tip,zeta_x\n1,0.02\n1.1\n");
  EXPECT_NE(ragged.find("line 3"), std::string::npos) << ragged;
}

}  // namespace

}  // namespace test_job_draws_cpp
