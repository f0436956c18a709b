// The job schema (include/robomill/job/job_schema.hpp) against the parser and
// the generated reference. The parser takes every section's accepted keys
// from the schema (SectionReader::allow_schema), so it cannot accept a key the
// schema lacks; these tests check the other direction: every schema field is
// read by the parser (the example jobs plus kitchen-sink jobs exercise them
// all), the parser reads no key its schema section lacks, and the reference
// lists every field.

#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>

#include "robomill/core/error.hpp"
#include "robomill/job/job.hpp"
#include "robomill/job/job_schema.hpp"

namespace test_job_schema_cpp {

namespace {

using namespace robomill;
namespace schema = job::schema;

const std::filesystem::path kExamples = std::filesystem::path(ROBOMILL_SOURCE_DIR) / "examples";

std::string field_id(const schema::Field& f) {
  return std::string(f.section) + "." + std::string(f.key);
}

TEST(JobSchema, SectionsAndFieldsAreConsistent) {
  std::set<std::string_view> ids;
  for (const schema::Section& s : schema::sections()) {
    EXPECT_TRUE(ids.insert(s.id).second) << "section listed twice: " << s.id;
    EXPECT_FALSE(s.description.empty()) << s.id;
    const auto& keys = schema::keys(s.id);
    EXPECT_FALSE(keys.empty()) << "section without fields: " << s.id;
    const std::set<std::string_view> unique(keys.begin(), keys.end());
    EXPECT_EQ(unique.size(), keys.size()) << "a key listed twice in " << s.id;
  }
  for (const schema::Field& f : schema::fields()) {
    EXPECT_TRUE(ids.count(f.section)) << field_id(f);
    EXPECT_FALSE(f.description.empty()) << field_id(f);
    // A unit must parse: the dimension column comes from it.
    if (!f.unit.empty()) {
      EXPECT_NO_THROW(schema::dimension(f)) << field_id(f);
    }
    // A map or list field names the section that describes its items.
    if (f.kind == schema::Kind::map || f.kind == schema::Kind::list) {
      const std::string child = std::string(schema::path(f));
      const bool described = ids.count(child) || ids.count(child + "[]") ||
                             (f.section == "job" && (ids.count(f.key) || ids.count(child + "[]")));
      const bool refers = f.description.find('`') != std::string_view::npos;
      EXPECT_TRUE(described || refers) << field_id(f);
    }
  }
  EXPECT_THROW(schema::keys("no.such.section"), std::logic_error);
}

TEST(JobSchema, ParserRejectsAKeyOutsideTheSchema) {
  try {
    job::parse_job("tool: {diameter: 10 mm, teeth: 2, colour: red}\n", "job.yaml");
    FAIL() << "unknown key accepted";
  } catch (const InputError& e) {
    const std::string text = e.what();
    EXPECT_NE(text.find("tool.colour"), std::string::npos) << text;
    // The message lists the schema's keys, in the schema's order.
    EXPECT_NE(text.find("type, corner_radius, diameter, teeth, helix, overhang, E, runout"),
              std::string::npos)
        << text;
  }
}

TEST(JobSchema, ReferenceListsEveryField) {
  const std::string page = schema::markdown();
  for (const schema::Field& f : schema::fields())
    EXPECT_NE(page.find("| `" + schema::path(f) + "` |"), std::string::npos) << field_id(f);
  for (const schema::Section& s : schema::sections())
    EXPECT_NE(page.find(std::string(s.description)), std::string::npos) << s.id;
}

// Jobs exercising the fields the examples leave out (together with the
// examples, every field of the schema).
const char* const kKitchenSinks[] = {
    // The exponential law; measured FRFs by direction, fit bands; output; a
    // robot base frame.
    R"(name: kitchen sink 1
tool: {diameter: 12 mm, teeth: 2, helix: 30 deg, overhang: 50 mm}
cutting: {law: exponential, kF: 500 N/mm, exponent: 0.8, chip_unit: 1 mm, kr: 0.3, ka: 0.1}
process: {spindle: 3210 rpm, feed_per_tooth: 0.05 mm, ap: 1 mm, ae: 12 mm}
dynamics:
  frf:
    x: {file: data/003_kr270_tab1.uff, format: uff58, response: x, reference: x}
    y: data/003_kr270_tab1.uff
    z: data/003_kr270_tab1.uff
  fit:
    max_order: 30
    bands: [{from: 10 Hz, to: 100 Hz, max_order: 20}, {from: 100 Hz, to: 6000 Hz}]
robot:
  dh: [{a: 0, alpha: 0, d: 0, theta: 0}]
  joint_stiffness: [1e6]
  base: {xyz: [0, 0, 100], rpy: [0, 0, 90]}
experiments:
  - {position: [120, 80, 5], frf: [{file: data/003_kr270_tab1.uff}]}
output: {dir: out/kitchen-sink, formats: [csv, json]}
)",
    // A simulation by revolutions with process damping; the deflection sweep.
    R"(name: kitchen sink 2
tool: {diameter: 10 mm, teeth: 2, overhang: 40 mm}
cutting: {law: linear, Ktc: 800 N/mm^2, Krc: 200 N/mm^2}
process: {spindle: 6000 rpm, feed_per_tooth: 0.05 mm, ap: 2 mm, ae: 2 mm, direction: down}
simulation:
  model: rigid
  revolutions: 20
  process_damping: {Ksp: 1.5e14 N/m^3, wear_land: 40 um, mu: 0.3}
  workpiece_mesh: {border: 1 mm}
deflection:
  depths: {from: 1 mm, to: 4 mm, count: 4}
)",
    // A program on a stock an earlier run left (stock.csv), with a size limit,
    // and the redundancy angles --optimize would try.
    R"(name: kitchen sink 3
tool: {diameter: 10 mm, teeth: 3, overhang: 40 mm}
cutting: {law: linear, Ktc: 800 N/mm^2}
toolpath: {file: programs/pocket.nc, max_size: 8}
stock: {box: {min: [0, 0, 0], max: [60, 40, 20]}, height_map: earlier/stock.csv}
robot_path:
  redundancy_search: {from: -30 deg, to: 30 deg, count: 5, per_line: true, joint_speed_max: 15 deg/s}
  deflection: contact
  offset: {measure: rms, harmonics: 20, samples: 64}
  compensation: {floor: true, min_offset: 2 um, tolerance: 3 um}
)",
    // An NX CLSF in inches without a UNITS record, cut with a bull nose.
    R"(name: kitchen sink nx
tool: {type: bull, diameter: 12.7 mm, corner_radius: 1.524 mm, teeth: 4, overhang: 40 mm}
cutting: {law: linear, Ktc: 800 N/mm^2}
toolpath: {file: programs/profile.cls, units: inch, spindle: 6000 rpm}
stock: {box: {min: [0, 0, -10], max: [60, 40, 0]}}
)",
    // robomill listen: one recording with every key, and the detector's settings.
    R"(name: kitchen sink 4
recording:
  file: cut.csv
  format: csv
  channel: 1
  column: ax
  sample_rate: 10 kHz
  signal: acceleration
  scale: 9.80665
  start: 1 s
  duration: 5 s
  ignore: [400 Hz]
  ignore_width: 2 Hz
  tachometer: once_per_rev
  tachometer_pulses: 2
  spindle: 3000 rpm
  depth: 1 mm
  note: every key
listen:
  teeth: 1
  spindle_search: 5 %
  threshold: 0.6
  mains: off
  steady_lines: false
  band: [10 Hz, 4 kHz]
  segment: 0.5 s
  spindle_range: [1000 rpm, 5000 rpm]
)",
    // Several recordings, each with every key.
    R"(name: kitchen sink 5
listen: {teeth: 2}
recordings:
  - {file: a.mat, format: mat, channel: 1, variable: tsDS, column: "2", sample_rate: 10 kHz,
     signal: displacement, scale: 1e-3, start: 0 s, duration: 2 s, ignore: [50 Hz],
     ignore_width: 1 Hz, tachometer: "3", tachometer_pulses: 1, spindle: 425 rpm, depth: 0.5 mm,
     note: first}
)",
    // Uncertain inputs: every key of uncertainty: and of its variables.
    R"(name: kitchen sink 6
dynamics:
  modes:
    - {direction: x, fn: 2060 Hz, zeta: 2.4 %, k: 8.1e6 N/m}
    - {direction: y, fn: 2150 Hz, zeta: 2.1 %, k: 9.3e6 N/m}
cutting: {law: linear, Ktc: 855 N/mm^2, Krc: 290 N/mm^2}
uncertainty:
  samples: 512
  seed: 3
  sampling: random
  posterior: posterior.csv
  variables:
    - {name: k_tip, path: [dynamics.modes.0.k, dynamics.modes.1.k], mode: scale,
       distribution: lognormal, median: 1, sigma: 0.2}
    - {name: zeta_x, path: dynamics.modes.0.zeta, mode: value, distribution: normal,
       mean: 2.4 %, sd: 10 %}
    - {name: ktc, path: cutting.Ktc, distribution: truncated_normal, mean: 855, sd: 90, min: 0,
       max: 2000}
    - {name: krc, path: cutting.Krc, distribution: uniform, min: 250, max: 330}
  correlation: {k_tip: {zeta_x: -0.3}}
)",
    // Learning from tests: every key of learn: and a heard chatter frequency.
    R"(name: kitchen sink 7
dynamics:
  modes:
    - {direction: x, fn: 2060 Hz, zeta: 2.4 %, k: 8.1e6 N/m}
cutting: {law: linear, Ktc: 855 N/mm^2, Krc: 290 N/mm^2}
experiments:
  - {spindle: 5130 rpm, depth: 1.7 mm, chatter: true, chatter_freq: 2113 Hz, power: 1.2 kW}
  - {spindle: 5210 rpm, depth: 1.2 mm, recording: {file: listen/displacement_stable.wav}}
  - {spindle: 5330 rpm, depth: 0.9 mm, chatter: false, ae: 1.5 mm, direction: up,
     feed_per_tooth: 0.08 mm}
  - {frf: {x: {file: x.csv, units: mm/N}, y: {file: y.csv, units: mm/N}}}
uncertainty:
  variables:
    - {name: k, path: dynamics.modes.0.k, mode: scale, distribution: lognormal, median: 1, sigma: 0.2}
learn:
  strategy: information
  max_risk: 30 %
  samples: 2000
  seed: 11
  verdict_sd: 0.05 mm
  verdict_relative_sd: 4 %
  mislabel: 2 %
  chatter_freq_sd: 15 Hz
  power_sd: 30 W
  method: sdm
  frf_fn_sd: 3 %
  frf_k_sd: 25 %
  frf_zeta_sd: 40 %
  spread_shrink: 3 %
)",
};

TEST(JobSchema, ExamplesAndKitchenSinksReadEveryField) {
  schema::CoverageRecorder recorder;
  int parsed = 0;
  // Every example job, those in examples/listen/ and examples/learn/ too.
  for (const auto& entry : std::filesystem::recursive_directory_iterator(kExamples)) {
    if (entry.path().extension() != ".yaml")
      continue;
    SCOPED_TRACE(entry.path().filename().string());
    EXPECT_NO_THROW(job::load_job(entry.path()));
    ++parsed;
  }
  EXPECT_GE(parsed, 10);
  int sink = 0;
  for (const char* text : kKitchenSinks) {
    SCOPED_TRACE("kitchen sink " + std::to_string(sink++));
    try {
      job::parse_job(text, kExamples / "kitchen_sink.yaml");
    } catch (const InputError& e) {
      ADD_FAILURE() << e.what();
    }
  }
  std::set<std::string> unread;
  for (const schema::Field& f : schema::fields()) {
    if (!recorder.read().count(field_id(f)))
      unread.insert(field_id(f));
  }
  std::string list;
  for (const auto& id : unread)
    list += "\n  " + id;
  EXPECT_TRUE(unread.empty()) << unread.size() << " schema fields no job read:" << list;
}

}  // namespace

}  // namespace test_job_schema_cpp
