#include "job_parser_learning.hpp"

#include <climits>

#include "quantity_fields.hpp"

namespace robomill::job::detail {

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
