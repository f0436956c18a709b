#include "job_parser_learning.hpp"

#include <climits>

#include "job_parser_cutting.hpp"
#include "job_parser_dynamics.hpp"
#include "job_parser_monitoring.hpp"
#include "job_parser_stability.hpp"
#include "quantity_fields.hpp"

namespace robomill::job::detail {

namespace {

/// A hammer test (`frf:`): the FRF files and where they were measured; no
/// cut, so none of a cut's keys.
void read_hammer_test(SectionReader& e, const Job& job, Experiment& experiment) {
  for (const char* key : {"spindle", "depth", "chatter", "chatter_freq", "power", "recording", "ae",
                          "direction", "feed_per_tooth"}) {
    if (e.has(key))
      e.fail(key,
             "belongs to a cut, and this entry is a hammer test (frf:): give the cut in "
             "an entry of its own");
  }
  experiment.frf_files = read_frf_files(e, job.source);
  experiment.verdict_given = false;
}

/// The cut of a test where it differs from the job's process.
void read_test_cut(SectionReader& e, const Job& job, Experiment& experiment) {
  if (e.has("ae"))
    experiment.radial_depth_m = read_radial_depth(e, job.tool);
  if (e.has("direction"))
    experiment.direction = read_direction(e);
  if (e.has("feed_per_tooth"))
    experiment.feed_per_tooth_m = e.quantity("feed_per_tooth", length_mm());
}

}  // namespace

std::vector<Experiment> read_experiments(SectionReader& root, const Job& job) {
  std::vector<Experiment> experiments;
  auto items = root.sections("experiments");
  if (!items)
    return experiments;
  for (SectionReader& e : *items) {
    e.allow_schema("experiments[]");
    Experiment experiment;
    experiment.line = e.line();
    if (e.has("posture") && e.has("position"))
      e.fail("position", "conflicts with posture: give the test's place once");
    if (e.has("posture")) {
      if (!job.robot)
        e.fail("posture", "needs a robot: section (the joint angles of its posture)");
      experiment.posture_rad = *e.quantities("posture", field(dimensions::angle, kDeg, "deg"),
                                             job.robot->description.joints.size());
    }
    if (e.has("position")) {
      if (!job.robot)
        e.fail("position", "needs a robot: section (and workpiece.pose: where the part sits)");
      const auto p = *e.quantities("position", length_mm({}), 3);
      experiment.position_m = Eigen::Vector3d(p[0], p[1], p[2]);
    }
    if (e.has("frf")) {
      read_hammer_test(e, job, experiment);
      e.finish();
      experiments.push_back(experiment);
      continue;
    }
    experiment.spindle_rad_s =
        e.quantity("spindle", field(dimensions::angular_speed, kRpm, "rpm", kPositive));
    experiment.axial_depth_m = e.quantity("depth", length_mm());
    read_test_cut(e, job, experiment);
    if (auto recording = e.section("recording")) {
      experiment.recording = read_nested_recording(*recording, job, experiment.spindle_rad_s);
      if (!experiment.recording->depth_m)
        experiment.recording->depth_m = experiment.axial_depth_m;
    }
    experiment.verdict_given = e.has("chatter");
    if (experiment.verdict_given)
      experiment.chatter = e.boolean("chatter");
    else if (!experiment.recording)
      e.fail("chatter", "required: true or false (or a recording: whose verdict says)");
    experiment.chatter_frequency_hz =
        e.quantity_or("chatter_freq", field(dimensions::frequency, 1.0, "Hz", kPositive), 0.0);
    experiment.power_w = e.quantity_or("power", field(dimensions::power, 1.0, "W", kPositive), 0.0);
    if (experiment.chatter_frequency_hz > 0.0 && !experiment.chatter)
      e.fail("chatter_freq", "is given for a test that did not chatter (chatter: false)");
    e.finish();
    experiments.push_back(experiment);
  }
  return experiments;
}

void read_learn(SectionReader& root, Job& job) {
  auto section = root.section("learn");
  if (!section)
    return;
  SectionReader& r = *section;
  r.allow_schema("learn");
  LearnSettings s;
  s.line = r.line();
  const std::string strategy =
      r.choice("strategy", {"switching", "information", "productivity"}, "switching");
  s.strategy = strategy == "information"    ? LearnSettings::Strategy::information
               : strategy == "productivity" ? LearnSettings::Strategy::productivity
                                            : LearnSettings::Strategy::switching;
  s.max_risk = r.quantity_or("max_risk", dimensionless(kPositive, Bound{1.0, false}), 0.5);
  s.samples = r.integer_or("samples", 100, 200000, 4000);
  const std::uint64_t default_seed = job.uncertainty ? job.uncertainty->seed : 1;
  s.seed = static_cast<std::uint64_t>(r.integer_or(
      "seed", 0, INT_MAX, static_cast<int>(std::min<std::uint64_t>(default_seed, INT_MAX))));
  s.verdict_sd_m = r.quantity_or("verdict_sd", length_mm(kPositive), 0.1e-3);
  s.verdict_relative_sd =
      r.quantity_or("verdict_relative_sd", dimensionless(kNonNegative, Bound{1.0, false}), 0.05);
  s.mislabel = r.quantity_or("mislabel", dimensionless(kNonNegative, Bound{0.5, false}), 0.01);
  s.chatter_freq_sd_hz =
      r.quantity_or("chatter_freq_sd", field(dimensions::frequency, 1.0, "Hz", kPositive), 20.0);
  s.power_sd_w = r.quantity_or("power_sd", field(dimensions::power, 1.0, "W", kPositive), 20.0);
  s.method = read_stability_method(r, "zoa");
  s.frf_fn_sd = r.quantity_or("frf_fn_sd", dimensionless(kPositive), 0.02);
  s.frf_k_sd = r.quantity_or("frf_k_sd", dimensionless(kPositive), 0.20);
  s.frf_zeta_sd = r.quantity_or("frf_zeta_sd", dimensionless(kPositive), 0.30);
  s.spread_shrink =
      r.quantity_or("spread_shrink", dimensionless(kNonNegative, Bound{1.0, false}), 0.05);
  if (auto places = r.sections("places")) {
    for (SectionReader& place : *places) {
      place.allow_schema("learn.places[]");
      if (!job.robot)
        place.fail("posture", "needs a robot: section (the joint angles of its posture)");
      const auto posture = place.quantities("posture", field(dimensions::angle, kDeg, "deg"),
                                            job.robot->description.joints.size());
      if (!posture)
        place.fail("posture", "required: the robot's joint angles there (deg)");
      s.places_rad.push_back(*posture);
      place.finish();
    }
  }
  r.finish();
  job.learn = s;
}

}  // namespace robomill::job::detail
