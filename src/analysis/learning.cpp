#include "robomill/analysis/learning.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include "robomill/analysis/job_draws.hpp"
#include "robomill/analysis/learning_model.hpp"
#include "robomill/analysis/recording_verdicts.hpp"
#include "robomill/analysis/structure.hpp"
#include "robomill/core/constants.hpp"
#include "robomill/core/error.hpp"
#include "robomill/core/parallel.hpp"
#include "robomill/cutting/engagement.hpp"
#include "robomill/job/units.hpp"
#include "robomill/learning/stability_evidence.hpp"
#include "robomill/stability/lobes.hpp"
#include "robomill/uncertainty/sample_statistics.hpp"

namespace robomill::analysis {
namespace {

using job::LearnSettings;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// Experiments at speeds closer than this (relative) count as one speed when
/// looking for contradictions.
constexpr double kSameSpeed = 0.005;
/// A verdict the prior gives less than this probability is reported.
constexpr double kSurprise = 1e-3;
/// The next test is chosen on at most this many posterior samples (evenly
/// spaced): the expected information's Monte-Carlo error is then about 1 %.
constexpr Eigen::Index kSelectionSamples = 1000;

LearnSettings settings_of(const job::Job& job) {
  if (job.learn)
    return *job.learn;
  LearnSettings s;
  s.seed = job.uncertainty ? job.uncertainty->seed : 1;
  return s;
}

learning::VerdictModel verdict_model(const LearnSettings& s) {
  return {s.verdict_sd_m, s.verdict_relative_sd, s.mislabel};
}

/// The experiments as the likelihood reads them: each one's place (a
/// robot's posture) and its speed in that place's list of distinct speeds,
/// so a sample solves each place and speed once.
/// A test's mean spindle power as the linear law gives it: P = Ω T̄,
/// T̄ = (D/2) N ap/2π ∫(Ktc fz sin φ + Kte) dφ over the engagement
/// (Altintas, Manufacturing Automation, Eq 2.51's tangential part), linear in
/// (Ktc, Kte): P = per_ktc Ktc + per_kte Kte.
struct PowerBasis {
  double per_ktc = 0.0;  ///< W per (N/m²)
  double per_kte = 0.0;  ///< W per (N/m)
};

PowerBasis power_basis(const job::Job& job, const job::Experiment& t) {
  const cutting::MillingProcess& p = *job.process;
  const double radius = 0.5 * job.tool->diameter_m;
  const cutting::Engagement e =
      cutting::radial_engagement(radius, radius, t.radial_depth_m.value_or(p.radial_depth_m),
                                 t.direction.value_or(p.direction));
  const double common =
      t.spindle_rad_s * radius * job.tool->teeth * t.axial_depth_m / (2.0 * std::numbers::pi);
  return {common * t.feed_per_tooth_m.value_or(p.feed_per_tooth_m) *
              (std::cos(e.entry_rad) - std::cos(e.exit_rad)),
          common * (e.exit_rad - e.entry_rad)};
}

/// A mode fitted to a hammer test's FRF: its direction (the driving-point
/// axis), fn, ζ and the modal stiffness k = ωn²/φ² along that axis.
struct ObservedMode {
  std::size_t test = 0;  ///< in job.experiments
  int place = 0;
  int axis = 0;
  double natural_frequency_hz = 0.0, damping_ratio = 0.0, stiffness_n_per_m = 0.0;
};

/// The cuts' evidence grouped by where (place) and how (cut: ae, direction)
/// each was made, so a sample solves each place, cut and speed once.
struct Evidence {
  std::vector<job::Experiment> tests;
  std::vector<PowerBasis> power;                  ///< per test (used where it gives a power)
  std::vector<int> group_of;                      ///< per test: its (place, cut)
  std::vector<std::size_t> speed_of;              ///< per test, in its group's list
  std::vector<std::pair<int, int>> groups;        ///< (place, cut)
  std::vector<std::vector<double>> speeds_rad_s;  ///< per group
  std::vector<ObservedMode> hammer;               ///< the hammer tests' fitted modes
  std::vector<int> hammer_places;                 ///< the places they were measured at
};

Evidence evidence_of(const LearningModel& model, const job::Job& job,
                     const std::vector<job::Experiment>& tests,
                     const std::vector<ObservedMode>& hammer) {
  Evidence e;
  e.tests = tests;
  e.hammer = hammer;
  for (const ObservedMode& m : hammer)
    if (std::find(e.hammer_places.begin(), e.hammer_places.end(), m.place) == e.hammer_places.end())
      e.hammer_places.push_back(m.place);
  for (const job::Experiment& t : tests) {
    e.power.push_back(power_basis(job, t));
    const std::pair<int, int> group = {model.place_of(t.posture_rad), model.cut_of(t)};
    auto g = std::find(e.groups.begin(), e.groups.end(), group);
    if (g == e.groups.end()) {
      e.groups.push_back(group);
      e.speeds_rad_s.emplace_back();
      g = e.groups.end() - 1;
    }
    std::vector<double>& speeds = e.speeds_rad_s[static_cast<std::size_t>(g - e.groups.begin())];
    const auto it = std::find(speeds.begin(), speeds.end(), t.spindle_rad_s);
    e.group_of.push_back(static_cast<int>(g - e.groups.begin()));
    e.speed_of.push_back(static_cast<std::size_t>(it - speeds.begin()));
    if (it == speeds.end())
      speeds.push_back(t.spindle_rad_s);
  }
  return e;
}

/// log p(fitted mode | predicted modes): the hammer test's fitted fn, k and
/// ζ against the predicted mode nearest to them (the smallest normalized
/// distance in log fn, log k along the measured axis, log ζ), each
/// log-normal with the learn.frf_*_sd spreads. A predicted mode without
/// motion along the axis cannot be the one measured there.
double log_hammer_likelihood(const ObservedMode& observed,
                             const std::vector<dynamics::Mode>& predicted,
                             const LearnSettings& settings, std::size_t* nearest = nullptr) {
  double best = kInfinity;
  for (std::size_t r = 0; r < predicted.size(); ++r) {
    const dynamics::Mode& m = predicted[r];
    const double along = m.shape(observed.axis);
    if (!(along * along > 0.0))
      continue;
    const double omega = 2.0 * std::numbers::pi * m.natural_frequency_hz;
    const double k = omega * omega / (along * along);
    const double rf =
        std::log(observed.natural_frequency_hz / m.natural_frequency_hz) / settings.frf_fn_sd;
    const double rk = std::log(observed.stiffness_n_per_m / k) / settings.frf_k_sd;
    const double rz = std::log(observed.damping_ratio / m.damping_ratio) / settings.frf_zeta_sd;
    const double distance = rf * rf + rk * rk + rz * rz;
    if (distance < best && nearest)
      *nearest = r;
    best = std::min(best, distance);
  }
  if (!std::isfinite(best))
    return -kInfinity;
  // The three log-normal densities of the observed values.
  const double norm = std::log(settings.frf_fn_sd * settings.frf_k_sd * settings.frf_zeta_sd *
                               observed.natural_frequency_hz * observed.stiffness_n_per_m *
                               observed.damping_ratio) +
                      1.5 * std::log(2.0 * std::numbers::pi);
  return -0.5 * best - norm;
}

double limit_or_infinity(const stability::ZeroOrderLimit& l) {
  return l.limited ? l.depth_limit_m : kInfinity;
}

/// log p(experiments | values x): the verdicts' probits and the chatter
/// frequencies' normal terms (learning/stability_evidence.hpp), the tests
/// before `first_added` in `settled`, the others in `added`.
learning::LogLikelihoodParts log_likelihood(const LearningModel& model, const Evidence& evidence,
                                            const LearnSettings& settings, const Eigen::VectorXd& x,
                                            std::size_t first_added) {
  learning::LogLikelihoodParts parts;
  if (!evidence.hammer.empty()) {
    std::vector<dynamics::Mode> modes;
    for (const int place : evidence.hammer_places) {
      if (!model.modes(x, place, modes))
        return {-kInfinity, -kInfinity};
      for (const ObservedMode& m : evidence.hammer)
        if (m.place == place)
          parts.settled += log_hammer_likelihood(m, modes, settings);
    }
  }
  if (evidence.tests.empty())
    return parts;
  std::vector<std::vector<stability::ZeroOrderLimit>> limits(evidence.speeds_rad_s.size());
  for (std::size_t g = 0; g < limits.size(); ++g) {
    const std::vector<double>& speeds = evidence.speeds_rad_s[g];
    limits[g].resize(speeds.size());
    if (!model.limits(x, evidence.groups[g].first, evidence.groups[g].second, speeds, limits[g]))
      return {-kInfinity, -kInfinity};
  }
  const learning::VerdictModel verdict = verdict_model(settings);
  for (std::size_t i = 0; i < evidence.tests.size(); ++i) {
    const job::Experiment& t = evidence.tests[i];
    const stability::ZeroOrderLimit& l =
        limits[static_cast<std::size_t>(evidence.group_of[i])][evidence.speed_of[i]];
    double term =
        learning::log_verdict_likelihood(t.chatter, t.axial_depth_m, limit_or_infinity(l), verdict);
    if (t.chatter && t.chatter_frequency_hz > 0.0 && l.limited) {
      const double tooth_hz = model.teeth() * t.spindle_rad_s / (2.0 * std::numbers::pi);
      term += learning::log_chatter_frequency_likelihood(
          t.chatter_frequency_hz, l.chatter_frequency_hz, tooth_hz, settings.chatter_freq_sd_hz);
    }
    if (t.power_w > 0.0) {
      const std::optional<cutting::LinearLaw> law = model.law_of(x);
      const double predicted =
          evidence.power[i].per_ktc * law->Ktc_pa + evidence.power[i].per_kte * law->Kte_n_per_m;
      const double r = (t.power_w - predicted) / settings.power_sd_w;
      term += -0.5 * r * r - std::log(settings.power_sd_w * std::sqrt(2.0 * std::numbers::pi));
    }
    (i < first_added ? parts.settled : parts.added) += term;
  }
  return parts;
}

/// The posterior of every test but the latest, and of all of them: the
/// first sampled from the prior, then extended to the latest test
/// (learning::extend_tempered).
struct Posteriors {
  learning::SmcPosterior without_latest, all;
};

Posteriors sample(const LearningModel& model, const Evidence& evidence,
                  const LearnSettings& settings, int threads) {
  learning::SmcSettings smc;
  smc.particles = settings.samples;
  smc.seed = settings.seed;
  smc.threads = threads;
  // The latest cut is sampled apart (the switching strategy's posterior
  // without it); hammer tests are always settled.
  const std::size_t latest = evidence.tests.empty() ? 0 : evidence.tests.size() - 1;
  Posteriors p;
  p.without_latest = learning::sample_tempered(
      model.dimension(),
      [&](const Eigen::VectorXd& w) {
        return log_likelihood(model, evidence, settings, model.values_of(w), latest).settled;
      },
      smc);
  if (evidence.tests.empty()) {
    p.all = p.without_latest;
    return p;
  }
  p.all = learning::extend_tempered(
      p.without_latest,
      [&](const Eigen::VectorXd& w) {
        return log_likelihood(model, evidence, settings, model.values_of(w), latest);
      },
      smc);
  return p;
}

Eigen::MatrixXd values_of(const LearningModel& model, const Eigen::MatrixXd& w) {
  Eigen::MatrixXd x(w.rows(), w.cols());
  for (Eigen::Index i = 0; i < w.rows(); ++i)
    x.row(i) = model.values_of(w.row(i).transpose()).transpose();
  return x;
}

/// The band of `values` (samples × variables) at `speeds`: every sample's
/// limits, then stability's summary (quantile lobes, P(chatter) map).
StabilityBand band_of(const LearningModel& model, const job::Job& job,
                      const Eigen::MatrixXd& values, const std::string& source,
                      const std::vector<double>& speeds, int threads, int place = 0) {
  StabilityBand band;
  band.draws = {model.names(), values, source};
  band.speeds_rad_s = speeds;
  const auto n = values.rows();
  const auto s_count = static_cast<Eigen::Index>(speeds.size());
  band.limits_m.resize(n, s_count);
  band.limited.resize(n, s_count);
  std::vector<char> refused(static_cast<std::size_t>(n), 0);
  core::parallel_blocks(
      static_cast<std::size_t>(n), threads, [&](std::size_t begin, std::size_t end) {
        std::vector<stability::ZeroOrderLimit> limits(speeds.size());
        for (std::size_t i = begin; i < end; ++i) {
          const auto row = static_cast<Eigen::Index>(i);
          if (!model.limits(values.row(row).transpose(), place, speeds, limits)) {
            refused[i] = 1;
            continue;
          }
          for (Eigen::Index s = 0; s < s_count; ++s) {
            // As the stability band: limited within depth_max, else depth_max.
            const auto& l = limits[static_cast<std::size_t>(s)];
            const bool limited = l.limited && l.depth_limit_m <= job.stability->depth_max_m;
            band.limited(row, s) = limited;
            band.limits_m(row, s) = limited ? l.depth_limit_m : job.stability->depth_max_m;
          }
        }
      });
  const auto first = std::find(refused.begin(), refused.end(), 1);
  if (first != refused.end()) {
    const auto i = static_cast<Eigen::Index>(first - refused.begin());
    std::string text;
    for (int j = 0; j < model.dimension(); ++j)
      text += fmt::format("{}{} = {:.6g}", j ? ", " : "",
                          model.names()[static_cast<std::size_t>(j)], values(i, j));
    throw InputError("uncertainty", job.uncertainty->line,
                     fmt::format("{} sample {} ({}) gives no structure (a damping ratio outside "
                                 "(0, 1), a non-positive stiffness or frequency, a negative "
                                 "coefficient): keep the priors inside (lognormal, "
                                 "truncated_normal)",
                                 source, i, text));
  }
  std::vector<stability::ZeroOrderLimit> nominal(speeds.size());
  model.limits(model.nominal_values(), place, speeds, nominal);
  for (const auto& l : nominal)
    band.nominal_limit_m.push_back(
        std::min(l.limited ? l.depth_limit_m : kInfinity, job.stability->depth_max_m));
  summarize_band(band, *job.stability, threads);
  return band;
}

/// The mean over the speeds and the bands of the 5-95 % width.
double mean_spread_m(const std::vector<const StabilityBand*>& bands) {
  double sum = 0.0;
  std::size_t count = 0;
  for (const StabilityBand* band : bands) {
    for (std::size_t s = 0; s < band->speeds_rad_s.size(); ++s, ++count)
      sum += band->q95_m[s].value - band->q05_m[s].value;
  }
  return count == 0 ? 0.0 : sum / static_cast<double>(count);
}

VariableSummary prior_summary(const uncertainty::Distribution& d) {
  return {uncertainty::mean(d), uncertainty::standard_deviation(d), uncertainty::quantile(d, 0.05),
          uncertainty::quantile(d, 0.5), uncertainty::quantile(d, 0.95)};
}

VariableSummary sample_summary(const Eigen::VectorXd& column) {
  const std::span<const double> v(column.data(), static_cast<std::size_t>(column.size()));
  return {uncertainty::sample_mean(v).value, uncertainty::sample_standard_deviation(v),
          uncertainty::empirical_quantile(v, 0.05).value,
          uncertainty::empirical_quantile(v, 0.5).value,
          uncertainty::empirical_quantile(v, 0.95).value};
}

Eigen::MatrixXd correlation_of(const Eigen::MatrixXd& values) {
  const Eigen::MatrixXd centred = values.rowwise() - values.colwise().mean();
  Eigen::MatrixXd c = centred.transpose() * centred;
  const Eigen::VectorXd sd = c.diagonal().cwiseSqrt();
  for (Eigen::Index i = 0; i < c.rows(); ++i) {
    for (Eigen::Index j = 0; j < c.cols(); ++j)
      c(i, j) = sd(i) > 0.0 && sd(j) > 0.0 ? c(i, j) / (sd(i) * sd(j)) : (i == j ? 1.0 : 0.0);
  }
  return c;
}

std::string describe_test(const job::Experiment& t, std::size_t index) {
  return fmt::format("experiments[{}] (line {}: {:.0f} rpm, {:.3g} mm, {})", index, t.line,
                     t.spindle_rad_s * kRpmPerRadS, t.axial_depth_m * 1e3,
                     t.chatter ? "chatter" : "stable");
}

/// The experiments as learned: each written verdict, or its recording's
/// (`listen`'s analysis: the verdict, the chatter line, the measured
/// spindle speed); a recording judged "unknown" is skipped with its reason.
struct ResolvedTests {
  std::vector<job::Experiment> used;
  std::vector<std::size_t> index;  ///< of each used test in job.experiments
  std::vector<bool> from_recording;
  std::vector<SkippedExperiment> skipped;
};

ResolvedTests resolve_tests(const LearningModel& model, const job::Job& job, int threads,
                            std::vector<std::string>& warnings) {
  ResolvedTests out;
  for (std::size_t i = 0; i < job.experiments.size(); ++i) {
    job::Experiment t = job.experiments[i];
    if (t.hammer())
      continue;  // hammer_modes
    t.posture_rad = model.experiment_posture(i);
    if (t.recording) {
      // listen's analysis of this one recording: the job's tool, process
      // and listen settings, no lobes (the verdict does not need them).
      job::Job one = job;
      one.stability.reset();
      one.recordings = {*t.recording};
      one.recordings_listed = true;
      RecordingVerdicts verdicts;
      try {
        verdicts = recording_verdicts(one, threads);
      } catch (const InputError& e) {
        throw InputError(fmt::format("experiments[{}].recording", i), t.line, e.what());
      }
      const monitoring::RecordingAnalysis& a = verdicts.recordings.front().analysis;
      if (a.verdict == monitoring::Verdict::unknown) {
        out.skipped.push_back({i, t.line, "its recording's verdict is unknown: " + a.reason});
        continue;
      }
      const bool heard = a.verdict == monitoring::Verdict::chatter;
      if (t.verdict_given && heard != t.chatter)
        warnings.push_back(fmt::format(
            "experiments[{}] (line {}): written chatter: {}, its recording says {}; the "
            "recording's verdict is used",
            i, t.line, t.chatter ? "true" : "false", heard ? "chatter" : "stable"));
      t.chatter = heard;
      t.chatter_frequency_hz = heard ? a.chatter_hz : 0.0;
      t.spindle_rad_s = 2.0 * std::numbers::pi * a.spindle_hz_measured;
    }
    out.used.push_back(t);
    out.index.push_back(i);
    out.from_recording.push_back(t.recording.has_value());
  }
  return out;
}

/// The hammer tests' fitted modes: each test's FRFs read (as dynamics.frf)
/// and fitted with the job's dynamics.fit settings, every fitted mode along
/// its driving-point axis.
std::vector<ObservedMode> hammer_modes(const LearningModel& model, const job::Job& job) {
  std::vector<ObservedMode> observed;
  for (std::size_t i = 0; i < job.experiments.size(); ++i) {
    const job::Experiment& t = job.experiments[i];
    if (!t.hammer())
      continue;
    job::Job one = job;
    one.frf_files = t.frf_files;
    std::optional<StructureFit> fit;
    try {
      fit.emplace(fit_structure(one, load_measured_frfs(one)));
    } catch (const InputError&) {
      throw;  // names the file's entry, experiments[i].frf...
    } catch (const Error& e) {
      throw InputError(fmt::format("experiments[{}].frf", i), t.line,
                       fmt::format("the hammer test's FRFs could not be fitted ({}): set "
                                   "dynamics.fit.bands around the modes the model describes",
                                   e.what()));
    }
    const int place = model.place_of(model.experiment_posture(i));
    for (const dynamics::Mode& m : fit->modes.modes()) {
      Eigen::Index axis = 0;
      const double along = m.shape.cwiseAbs().maxCoeff(&axis);
      const double omega = 2.0 * std::numbers::pi * m.natural_frequency_hz;
      observed.push_back({i, place, static_cast<int>(axis), m.natural_frequency_hz, m.damping_ratio,
                          omega * omega / (along * along)});
    }
  }
  return observed;
}

/// Each fitted mode's nearest predicted mode (fn, k along the axis), its
/// median over `values`.
void predicted_hammer_modes(const LearningModel& model, const Eigen::MatrixXd& values,
                            const std::vector<ObservedMode>& observed,
                            const LearnSettings& settings, bool posterior,
                            std::vector<LearnedHammerMode>& out) {
  const Eigen::Index stride = std::max<Eigen::Index>(1, values.rows() / kSelectionSamples);
  for (std::size_t k = 0; k < observed.size(); ++k) {
    const ObservedMode& o = observed[k];
    std::vector<double> fn, stiffness;
    std::vector<dynamics::Mode> modes;
    for (Eigen::Index i = 0; i < values.rows(); i += stride) {
      std::size_t r = 0;
      if (!model.modes(values.row(i).transpose(), o.place, modes) ||
          !std::isfinite(log_hammer_likelihood(o, modes, settings, &r)))
        continue;
      const double along = modes[r].shape(o.axis);
      const double omega = 2.0 * std::numbers::pi * modes[r].natural_frequency_hz;
      fn.push_back(modes[r].natural_frequency_hz);
      stiffness.push_back(omega * omega / (along * along));
    }
    if (fn.empty())
      continue;
    const double fn_median = uncertainty::empirical_quantile(fn, 0.5).value;
    const double k_median = uncertainty::empirical_quantile(stiffness, 0.5).value;
    LearnedHammerMode& m = out[k];
    (posterior ? m.posterior_fn_hz : m.prior_fn_hz) = fn_median;
    (posterior ? m.posterior_k_n_per_m : m.prior_k_n_per_m) = k_median;
  }
}

/// Pairs of tests at one speed where the deeper one was stable and the
/// shallower one chattered.
void warn_contradictions(const ResolvedTests& resolved, std::vector<std::string>& warnings) {
  const std::vector<job::Experiment>& tests = resolved.used;
  for (std::size_t i = 0; i < tests.size(); ++i) {
    for (std::size_t j = 0; j < tests.size(); ++j) {
      const job::Experiment &stable = tests[i], &chatter = tests[j];
      if (stable.chatter || !chatter.chatter || stable.axial_depth_m <= chatter.axial_depth_m)
        continue;
      if (std::abs(stable.spindle_rad_s - chatter.spindle_rad_s) >
          kSameSpeed * std::max(stable.spindle_rad_s, chatter.spindle_rad_s))
        continue;
      warnings.push_back(fmt::format(
          "{} and {} contradict each other: at one speed the deeper cut was stable and the "
          "shallower one chattered; the posterior weighs one of them as mislabelled "
          "(learn.mislabel)",
          describe_test(stable, resolved.index[i]), describe_test(chatter, resolved.index[j])));
    }
  }
}

/// The predicted P(chatter) of a test at (speed column, depth) over the
/// selection samples, and its expected information.
struct Candidate {
  double p_chatter = 0.0, information_bits = 0.0;
};

Candidate candidate_at(const StabilityBand& band, Eigen::Index speed, double depth_m,
                       const learning::VerdictModel& verdict, Eigen::Index stride,
                       std::vector<double>& scratch) {
  scratch.clear();
  for (Eigen::Index i = 0; i < band.limits_m.rows(); i += stride) {
    const double limit = band.limited(i, speed) ? band.limits_m(i, speed) : kInfinity;
    scratch.push_back(learning::chatter_probability(depth_m, limit, verdict));
  }
  double mean = 0.0;
  for (const double p : scratch)
    mean += p;
  return {mean / static_cast<double>(scratch.size()), learning::expected_information_bits(scratch)};
}

/// The next test by `strategy` ("information" or "productivity") among the
/// band's speeds × depths with P(chatter) ≤ max_risk.
NextTest choose_test_at(const job::Job& job, const StabilityBand& band,
                        const LearnSettings& settings, const std::string& strategy, int threads) {
  const learning::VerdictModel verdict = verdict_model(settings);
  const Eigen::Index stride = std::max<Eigen::Index>(1, band.limits_m.rows() / kSelectionSamples);
  const cutting::MillingProcess& process = *job.process;
  const std::size_t speeds = band.speeds_rad_s.size();
  std::vector<NextTest> best(speeds);
  core::parallel_for(speeds, threads, [&](std::size_t s) {
    std::vector<double> scratch;
    for (const double depth : band.depths_m) {
      const Candidate c =
          candidate_at(band, static_cast<Eigen::Index>(s), depth, verdict, stride, scratch);
      if (c.p_chatter > settings.max_risk)
        continue;
      const double rate = depth * process.radial_depth_m * process.feed_per_tooth_m *
                          job.tool->teeth * band.speeds_rad_s[s] / (2.0 * std::numbers::pi);
      NextTest t{true,        strategy,           "",  band.speeds_rad_s[s], depth,
                 c.p_chatter, c.information_bits, rate};
      const bool better = !best[s].found || (strategy == "information"
                                                 ? t.information_bits > best[s].information_bits
                                                 : t.removal_rate_m3_s > best[s].removal_rate_m3_s);
      if (better)
        best[s] = t;
    }
  });
  NextTest chosen;
  chosen.strategy = strategy;
  for (const NextTest& t : best) {
    if (!t.found)
      continue;
    const bool better = !chosen.found || (strategy == "information"
                                              ? t.information_bits > chosen.information_bits
                                              : t.removal_rate_m3_s > chosen.removal_rate_m3_s);
    if (better)
      chosen = t;
  }
  return chosen;
}

/// The next test over every place's posterior band (the first place's, then
/// a robot's others).
NextTest choose_test(const job::Job& job, const LearningResult& result,
                     const LearnSettings& settings, const std::string& strategy, int threads) {
  NextTest chosen = choose_test_at(job, result.posterior_band, settings, strategy, threads);
  for (std::size_t p = 0; p < result.more_places.size(); ++p) {
    NextTest t = choose_test_at(job, result.more_places[p].posterior, settings, strategy, threads);
    t.place = static_cast<int>(p) + 1;
    const bool better =
        t.found && (!chosen.found ||
                    (strategy == "information" ? t.information_bits > chosen.information_bits
                                               : t.removal_rate_m3_s > chosen.removal_rate_m3_s));
    if (better)
      chosen = t;
  }
  if (!chosen.found)
    chosen.reason = fmt::format(
        "no candidate in stability.speeds × depths up to stability.depth_max has P(chatter) ≤ "
        "{:.3g} (learn.max_risk)",
        settings.max_risk);
  return chosen;
}

/// What the samples predict for a test: each one's P(chatter) (the probit),
/// on at most kSelectionSamples of them, and with `family_hz` the predicted
/// family member nearest to the test's chatter frequency.
std::vector<double> predicted_chatter(const LearningModel& model, const Eigen::MatrixXd& values,
                                      const job::Experiment& test,
                                      const learning::VerdictModel& verdict,
                                      std::vector<double>* family_hz = nullptr) {
  const Eigen::Index stride = std::max<Eigen::Index>(1, values.rows() / kSelectionSamples);
  const std::vector<double> speed = {test.spindle_rad_s};
  std::vector<stability::ZeroOrderLimit> limit(1);
  std::vector<double> p;
  for (Eigen::Index i = 0; i < values.rows(); i += stride) {
    if (!model.limits(values.row(i).transpose(), model.place_of(test.posture_rad),
                      model.cut_of(test), speed, limit))
      continue;
    p.push_back(
        learning::chatter_probability(test.axial_depth_m, limit_or_infinity(limit[0]), verdict));
    if (family_hz && limit[0].limited)
      family_hz->push_back(learning::nearest_chatter_family_hz(
          test.chatter_frequency_hz, limit[0].chatter_frequency_hz,
          model.teeth() * test.spindle_rad_s / (2.0 * std::numbers::pi)));
  }
  return p;
}

double mean_of(const std::vector<double>& values) {
  double sum = 0.0;
  for (const double v : values)
    sum += v;
  return values.empty() ? 0.0 : sum / static_cast<double>(values.size());
}

/// The switching strategy's choice (issue 35: information until the
/// boundary's spread stops shrinking, then productivity), stateless: the
/// posterior without the latest test against the one with it. Only a test
/// that could teach (≥ kTeachingBits expected before it was run) is judged
/// by its shrink; after one that could not (a productivity cut well inside
/// the stable region), information again, so the choice never stays on
/// productivity while the boundary could still be learned. Sets `strategy`
/// and the result's spread without the latest test; returns the reason.
std::string switching_choice(const LearningModel& model, const job::Job& job,
                             const std::vector<job::Experiment>& tests,
                             const Posteriors& posteriors, const std::vector<double>& speeds,
                             const LearnSettings& settings, int threads, LearningResult& result,
                             std::string& strategy) {
  constexpr double kTeachingBits = 0.1;
  if (tests.size() < 2)
    return "fewer than two tests: information";
  const Eigen::MatrixXd before = values_of(model, posteriors.without_latest.particles);
  std::vector<StabilityBand> bands;
  for (std::size_t p = 0; p < model.places().size(); ++p)
    bands.push_back(band_of(model, job, before, "posterior without the latest test", speeds,
                            threads, static_cast<int>(p)));
  std::vector<const StabilityBand*> at;
  for (const StabilityBand& b : bands)
    at.push_back(&b);
  result.spread_before_last_m = mean_spread_m(at);
  const double shrink = 1.0 - result.posterior_spread_m / result.spread_before_last_m;
  const double taught = learning::expected_information_bits(
      predicted_chatter(model, before, tests.back(), verdict_model(settings)));
  if (taught < kTeachingBits)
    return fmt::format(
        "the latest test could teach {:.2f} bits (< {:.1f}: a cut inside the known region): "
        "information",
        taught, kTeachingBits);
  const bool still_learning = shrink >= settings.spread_shrink;
  if (!still_learning)
    strategy = "productivity";
  return fmt::format(
      "the boundary's spread shrank by {:.1f} % with the latest test ({} {:.1f} %, "
      "learn.spread_shrink): {}",
      100.0 * shrink, still_learning ? "≥" : "<", 100.0 * settings.spread_shrink, strategy);
}

}  // namespace

LearningResult learn(const job::Job& job, int threads) {
  const auto start = std::chrono::steady_clock::now();
  const LearningModel model(job);
  const LearnSettings settings = settings_of(job);
  LearningResult result;
  result.names = model.names();
  for (const job::UncertaintySettings::Variable& v : job.uncertainty->variables)
    result.units.push_back(v.mode == job::UncertaintySettings::Mode::scale
                               ? std::string("factor")
                               : job::si_unit(v.targets.front().dimension));

  const ResolvedTests resolved = resolve_tests(model, job, threads, result.warnings);
  result.skipped = resolved.skipped;
  const std::vector<ObservedMode> hammer = hammer_modes(model, job);
  const Evidence evidence = evidence_of(model, job, resolved.used, hammer);
  const Posteriors posteriors = sample(model, evidence, settings, threads);
  result.sampler = posteriors.all;
  result.posterior_values = values_of(model, result.sampler.particles);

  const job::StabilitySettings& s = *job.stability;
  const std::vector<double> speeds =
      stability::linear_range(s.speed_from_rad_s, s.speed_to_rad_s, s.speed_count);
  const JobDraws prior_draws = draw_job_inputs(job);
  result.prior_band = band_of(model, job, prior_draws.values, prior_draws.source, speeds, threads);
  result.posterior_band =
      band_of(model, job, result.posterior_values, "posterior", speeds, threads);
  result.places_rad = model.places();
  for (std::size_t p = 1; p < model.places().size(); ++p) {
    const int place = static_cast<int>(p);
    result.more_places.push_back(
        {model.places()[p],
         band_of(model, job, prior_draws.values, prior_draws.source, speeds, threads, place),
         band_of(model, job, result.posterior_values, "posterior", speeds, threads, place)});
  }
  std::vector<const StabilityBand*> priors = {&result.prior_band},
                                    posteriors_at = {&result.posterior_band};
  for (const PlaceBands& p : result.more_places) {
    priors.push_back(&p.prior);
    posteriors_at.push_back(&p.posterior);
  }
  result.prior_spread_m = mean_spread_m(priors);
  result.posterior_spread_m = mean_spread_m(posteriors_at);
  result.spread_before_last_m = std::numeric_limits<double>::quiet_NaN();

  for (int j = 0; j < model.dimension(); ++j) {
    result.prior.push_back(prior_summary(model.priors()[static_cast<std::size_t>(j)]));
    result.posterior.push_back(sample_summary(result.posterior_values.col(j)));
  }
  result.posterior_correlation = correlation_of(result.posterior_values);

  // Every test's predicted verdict, before and after; the chatter frequency predicted.
  const learning::VerdictModel verdict = verdict_model(settings);
  for (std::size_t k = 0; k < resolved.used.size(); ++k) {
    const job::Experiment& t = resolved.used[k];
    const std::size_t i = resolved.index[k];
    LearnedExperiment e{
        i, t.line, t.spindle_rad_s, t.axial_depth_m, t.chatter, t.chatter_frequency_hz};
    e.from_recording = resolved.from_recording[k];
    e.place = model.place_of(t.posture_rad);
    if (t.power_w > 0.0) {
      e.power_w = t.power_w;
      const PowerBasis basis = evidence.power[k];
      std::vector<double> power;
      for (Eigen::Index row = 0; row < result.posterior_values.rows(); ++row) {
        if (const auto law = model.law_of(result.posterior_values.row(row).transpose()))
          power.push_back(basis.per_ktc * law->Ktc_pa + basis.per_kte * law->Kte_n_per_m);
      }
      if (!power.empty())
        e.predicted_power_w = uncertainty::empirical_quantile(power, 0.5).value;
    }
    e.p_chatter_prior = mean_of(predicted_chatter(model, prior_draws.values, t, verdict));
    std::vector<double> family;
    e.p_chatter_posterior =
        mean_of(predicted_chatter(model, result.posterior_values, t, verdict,
                                  t.chatter_frequency_hz > 0.0 ? &family : nullptr));
    if (!family.empty())
      e.predicted_chatter_frequency_hz = uncertainty::empirical_quantile(family, 0.5).value;
    // The prior's own probability of the verdict, the mislabel chance taken
    // out: mean P = ε/2 + (1 − ε) mean Φ.
    const double p_model =
        (e.p_chatter_prior - 0.5 * settings.mislabel) / (1.0 - settings.mislabel);
    const double p_verdict = t.chatter ? p_model : 1.0 - p_model;
    if (p_verdict < kSurprise)
      result.warnings.push_back(fmt::format(
          "{}: the prior gives this verdict a probability of {:.2g}: the variables can hardly "
          "reach it (check the test, or widen the priors)",
          describe_test(t, i), p_verdict));
    result.experiments.push_back(e);
  }
  warn_contradictions(resolved, result.warnings);
  for (const ObservedMode& o : hammer)
    result.hammer_modes.push_back({o.test, job.experiments[o.test].line, o.place, o.axis,
                                   o.natural_frequency_hz, o.damping_ratio, o.stiffness_n_per_m});
  predicted_hammer_modes(model, prior_draws.values, hammer, settings, false, result.hammer_modes);
  predicted_hammer_modes(model, result.posterior_values, hammer, settings, true,
                         result.hammer_modes);

  // The next test.
  std::string strategy =
      settings.strategy == LearnSettings::Strategy::productivity ? "productivity" : "information";
  std::string reason;
  if (settings.strategy == LearnSettings::Strategy::switching)
    reason = switching_choice(model, job, resolved.used, posteriors, speeds, settings, threads,
                              result, strategy);
  result.next = choose_test(job, result, settings, strategy, threads);
  if (result.next.reason.empty())
    result.next.reason = reason;
  result.elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace robomill::analysis
