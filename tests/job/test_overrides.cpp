// `--set key.path=value`: syntax, application before validation, and errors
// in overridden fields reported as coming from the command line.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "robomill/core/error.hpp"
#include "robomill/job/job.hpp"
#include "robomill/job/job_schema.hpp"

namespace test_overrides_cpp {

namespace {

using robomill::InputError;
using robomill::job::Job;
using robomill::job::Override;
using robomill::job::parse_job;
using robomill::job::parse_override;
namespace schema = robomill::job::schema;

constexpr double kDeg = std::numbers::pi / 180.0;

constexpr const char* kJob = R"(tool:
  diameter: 10
  teeth: 2
process:
  spindle: 6000
  feed_per_tooth: 0.1
  ap: 1
  ae: 2
dynamics:
  modes:
    - {direction: x, fn: 100, zeta: 0.02, k: 1e6}
    - {direction: y, fn: 200, zeta: 0.03, k: 2e6}
)";

Job with(std::initializer_list<const char*> assignments) {
  std::vector<Override> overrides;
  for (const char* assignment : assignments)
    overrides.push_back(parse_override(assignment));
  return parse_job(kJob, "job.yaml", overrides);
}

bool from_set(const InputError& error) {
  const std::string_view text = error.what();
  return text.ends_with("(from --set)");
}

InputError error_with(std::initializer_list<const char*> assignments) {
  try {
    with(assignments);
  } catch (const InputError& error) {
    return error;
  }
  ADD_FAILURE() << "overrides accepted";
  return InputError("", 0, "");
}

TEST(OverrideOption, ParsesKeyPathAndValue) {
  const Override simple = parse_override("process.ae=2 mm");
  EXPECT_EQ(simple.path, "process.ae");
  EXPECT_EQ(simple.value, "2 mm");
  // Only the first '=' splits: the value may contain more.
  const Override equals = parse_override("name=a=b");
  EXPECT_EQ(equals.path, "name");
  EXPECT_EQ(equals.value, "a=b");
  const Override indexed = parse_override(" dynamics.modes[1].fn = 250 Hz ");
  EXPECT_EQ(indexed.path, "dynamics.modes[1].fn");
  EXPECT_EQ(indexed.value, "250 Hz");
}

TEST(OverrideOption, RejectsBadSyntax) {
  for (const char* bad : {"process.ae", "=3", "process..ae=3", ".ae=3", "process.ae.=3",
                          "process.a-e=3", "process ae=3", "modes[x]=1", "modes[0=1", "a.b="}) {
    try {
      parse_override(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& error) {
      EXPECT_EQ(error.field(), "--set") << bad;
      EXPECT_EQ(error.line(), 0);
    }
  }
}

TEST(OverrideOption, ReplacesAValueBeforeValidation) {
  const Job job = with({"process.ae=4 mm", "tool.teeth=3"});
  EXPECT_NEAR(job.process->radial_depth_m, 4e-3, 1e-15);
  EXPECT_EQ(job.tool->teeth, 3);
  // Without overrides the file's value stands.
  EXPECT_NEAR(parse_job(kJob, "job.yaml").process->radial_depth_m, 2e-3, 1e-15);
}

TEST(OverrideOption, CreatesMissingSectionsAndKeys) {
  const Job job = with({"forces.revolutions=5", "tool.helix=30", "name=sweep 7"});
  EXPECT_EQ(job.forces.revolutions, 5);
  EXPECT_NEAR(job.tool->helix_rad, 30 * 3.14159265358979 / 180, 1e-9);
  EXPECT_EQ(job.name, "sweep 7");
}

TEST(OverrideOption, ValuesAreReadAsYaml) {
  const Job lists = with({"output.formats=[json]", "cutting={Ktc: 800, Krc: 200}"});
  EXPECT_TRUE(lists.output.json);
  EXPECT_FALSE(lists.output.csv);
  ASSERT_TRUE(lists.cutting.has_value());
  EXPECT_NEAR(std::get<robomill::cutting::LinearLaw>(*lists.cutting).Ktc_pa, 8e8, 1e-3);
}

TEST(OverrideOption, ListIndices) {
  const Job job = with({"dynamics.modes[1].fn=250 Hz"});
  EXPECT_DOUBLE_EQ(job.modes[1].natural_frequency_hz, 250.0);
  EXPECT_DOUBLE_EQ(job.modes[0].natural_frequency_hz, 100.0);
  const InputError out_of_range = error_with({"dynamics.modes[2].fn=250"});
  EXPECT_EQ(out_of_range.field(), "dynamics.modes");
  EXPECT_NE(std::string(out_of_range.what()).find("out of range"), std::string::npos);
}

TEST(OverrideOption, ErrorsInOverriddenFieldsSayFromSet) {
  const InputError error = error_with({"process.ae=-2 mm"});
  EXPECT_EQ(error.field(), "process.ae");
  EXPECT_EQ(error.line(), 0);
  EXPECT_STREQ(error.what(), "process.ae: must be positive, got -2 mm (from --set)");

  const InputError cross = error_with({"process.ae=12"});
  EXPECT_EQ(cross.field(), "process.ae");
  EXPECT_EQ(cross.line(), 0);
  EXPECT_NE(std::string(cross.what()).find("exceeds the tool diameter 10 mm (from --set)"),
            std::string::npos)
      << cross.what();

  const InputError typo = error_with({"tool.teth=3"});
  EXPECT_EQ(typo.field(), "tool.teth");
  EXPECT_EQ(typo.line(), 0);
  EXPECT_NE(std::string(typo.what()).find("unknown key"), std::string::npos);
  EXPECT_NE(std::string(typo.what()).find("--set"), std::string::npos);

  const InputError unit = error_with({"tool.diameter=10 rpm"});
  EXPECT_EQ(unit.line(), 0);
  EXPECT_NE(std::string(unit.what()).find("expected a length"), std::string::npos);
}

TEST(OverrideOption, SectionsCreatedBySetAreReportedAsSuch) {
  try {
    parse_job("name: x\n", "job.yaml", {parse_override("process.ae=2")});
    ADD_FAILURE() << "incomplete process section accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), "process.spindle");
    EXPECT_EQ(error.line(), 0);
    EXPECT_NE(std::string(error.what()).find("required field missing"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("(from --set)"), std::string::npos) << error.what();
  }
}

TEST(OverrideOption, FieldsNotOverriddenKeepTheirFileLines) {
  // The override is fine, but the file's ae exceeds the new diameter: the
  // error is about ae, on its line in the file.
  const InputError error = error_with({"tool.diameter=1.5"});
  EXPECT_EQ(error.field(), "process.ae");
  EXPECT_EQ(error.line(), 8);
  EXPECT_EQ(std::string(error.what()).find("--set"), std::string::npos) << error.what();
}

TEST(OverrideOption, PathThroughAValueIsAnError) {
  const InputError error = error_with({"tool.diameter.x=3"});
  EXPECT_EQ(error.field(), "tool.diameter");
  EXPECT_NE(std::string(error.what()).find("--set"), std::string::npos);
  const InputError index = error_with({"tool[0]=3"});
  EXPECT_EQ(index.field(), "tool");
  EXPECT_NE(std::string(index.what()).find("not a list"), std::string::npos);
}

TEST(OverrideOption, DeeplyNestedValueIsRejectedBeforeParsing) {
  const std::string value = "name=" + std::string(200, '[') + std::string(200, ']');
  try {
    parse_job(kJob, "job.yaml", {parse_override(value)});
    ADD_FAILURE() << "deep --set value accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), "name");
    EXPECT_EQ(error.line(), 0);
    EXPECT_NE(std::string(error.what()).find("nesting"), std::string::npos) << error.what();
  }
}

TEST(OverrideOption, InvalidYamlValue) {
  const InputError error = error_with({"process.ae=[1, 2"});
  EXPECT_EQ(error.field(), "process.ae");
  EXPECT_NE(std::string(error.what()).find("not valid YAML"), std::string::npos);
}

TEST(OverrideOption, DottedIndicesIndexLists) {
  const Job job = with({"dynamics.modes.1.fn=250 Hz", "dynamics.modes.0.zeta=2.5%"});
  EXPECT_DOUBLE_EQ(job.modes[1].natural_frequency_hz, 250.0);
  EXPECT_DOUBLE_EQ(job.modes[0].natural_frequency_hz, 100.0);
  EXPECT_NEAR(job.modes[0].damping_ratio, 0.025, 1e-15);
  EXPECT_NEAR(job.modes[1].damping_ratio, 0.03, 1e-15);
  // A whole entry, dotted or in brackets.
  const Job whole = with({"dynamics.modes.1={direction: x, fn: 300 Hz, zeta: 1 %, k: 5e6}"});
  ASSERT_EQ(whole.modes.size(), 2u);
  EXPECT_EQ(whole.modes[1].direction, 'x');
  EXPECT_DOUBLE_EQ(whole.modes[1].natural_frequency_hz, 300.0);
  EXPECT_DOUBLE_EQ(whole.modes[1].stiffness_n_per_m, 5e6);
  // Leading zeros are the same index.
  EXPECT_DOUBLE_EQ(with({"dynamics.modes.01.fn=260"}).modes[1].natural_frequency_hz, 260.0);
}

TEST(OverrideOption, WholeListInFlowForm) {
  const Job job =
      with({"dynamics.modes=[{direction: y, fn: 40 Hz, zeta: 2 %, k: 3e6}, "
            "{direction: x, fn: 50 Hz, zeta: 4 %, k: 4e6}, "
            "{direction: x, fn: 60 Hz, zeta: 5 %, k: 5e6}]"});
  ASSERT_EQ(job.modes.size(), 3u);
  EXPECT_EQ(job.modes[0].direction, 'y');
  EXPECT_DOUBLE_EQ(job.modes[2].natural_frequency_hz, 60.0);
  EXPECT_NEAR(job.modes[1].damping_ratio, 0.04, 1e-15);
  // A later override indexes the new list.
  EXPECT_DOUBLE_EQ(with({"dynamics.modes=[{direction: y, fn: 40, zeta: 0.02, k: 3e6}]",
                         "dynamics.modes.0.fn=45"})
                       .modes[0]
                       .natural_frequency_hz,
                   45.0);
}

TEST(OverrideOption, TheListsLengthAsLastStepAppends) {
  for (const char* path : {"dynamics.modes.2", "dynamics.modes[2]"}) {
    const Job job =
        with({(std::string(path) + "={direction: x, fn: 300, zeta: 0.01, k: 3e6}").c_str()});
    ASSERT_EQ(job.modes.size(), 3u) << path;
    EXPECT_DOUBLE_EQ(job.modes[2].natural_frequency_hz, 300.0) << path;
    EXPECT_DOUBLE_EQ(job.modes[1].natural_frequency_hz, 200.0) << path;
  }
  // Appended twice: the second index is the new length.
  EXPECT_EQ(with({"dynamics.modes.2={direction: x, fn: 300, zeta: 0.01, k: 3e6}",
                  "dynamics.modes.3={direction: y, fn: 400, zeta: 0.01, k: 3e6}"})
                .modes.size(),
            4u);
  // An appended entry is checked like any other, and its errors say so.
  const InputError bad = error_with({"dynamics.modes.2={direction: x, fn: 300, zeta: 0.01}"});
  EXPECT_EQ(bad.field().rfind("dynamics.modes[2]", 0), 0u) << bad.what();
  EXPECT_EQ(bad.line(), 0);
  EXPECT_NE(std::string(bad.what()).find("(from --set)"), std::string::npos) << bad.what();
}

TEST(OverrideOption, IndexPastTheEndNamesTheListsLength) {
  const InputError dotted = error_with({"dynamics.modes.5.zeta=2%"});
  EXPECT_EQ(dotted.field(), "dynamics.modes");
  EXPECT_EQ(dotted.line(), 0);
  EXPECT_STREQ(dotted.what(),
               "dynamics.modes: `--set dynamics.modes.5.zeta=2%`: index 5 is out of range; "
               "dynamics.modes has 2 entries (from --set)");
  const InputError bracket = error_with({"dynamics.modes[5].zeta=2%"});
  EXPECT_EQ(bracket.field(), "dynamics.modes");
  EXPECT_NE(
      std::string(bracket.what()).find("index 5 is out of range; dynamics.modes has 2 entries"),
      std::string::npos)
      << bracket.what();
  // The length itself appends only a whole entry.
  const InputError field_of_new = error_with({"dynamics.modes.2.zeta=2%"});
  EXPECT_NE(std::string(field_of_new.what())
                .find("index 2 is out of range; dynamics.modes has 2 entries (index 2 adds an "
                      "entry only as a whole: --set dynamics.modes.2=...) (from --set)"),
            std::string::npos)
      << field_of_new.what();
  // Huge indices are out of range too, not malformed paths or overflows.
  for (const char* huge :
       {"dynamics.modes.99999999999999999999999999.zeta=2%",
        "dynamics.modes[18446744073709551616].zeta=2%", "dynamics.modes[1000000000].zeta=2%"}) {
    const InputError error = error_with({huge});
    EXPECT_EQ(error.field(), "dynamics.modes") << huge;
    EXPECT_NE(std::string(error.what()).find("is out of range; dynamics.modes has 2 entries"),
              std::string::npos)
        << error.what();
  }
  // A one-entry list says "entry".
  const InputError one = error_with(
      {"dynamics.modes=[{direction: x, fn: 100, zeta: 0.02, k: 1e6}]", "dynamics.modes.3.fn=1"});
  EXPECT_NE(std::string(one.what()).find("dynamics.modes has 1 entry (from --set)"),
            std::string::npos)
      << one.what();
}

TEST(OverrideOption, NegativeIndicesAreRejected) {
  for (const char* assignment : {"dynamics.modes.-1.zeta=2%", "dynamics.modes[-1].zeta=2%"}) {
    try {
      parse_override(assignment);
      ADD_FAILURE() << "accepted " << assignment;
    } catch (const InputError& error) {
      EXPECT_EQ(error.field(), "--set");
      EXPECT_NE(std::string(error.what()).find("list indices count from 0, got -1"),
                std::string::npos)
          << error.what();
    }
    // The same through parse_job, which the Python module calls with
    // unparsed paths.
    const std::string text(assignment);
    const Override direct{text.substr(0, text.find('=')), "2%"};
    try {
      parse_job(kJob, "job.yaml", {direct});
      ADD_FAILURE() << "accepted " << assignment;
    } catch (const InputError& error) {
      EXPECT_EQ(error.field(), direct.path);
      EXPECT_NE(std::string(error.what()).find("list indices count from 0, got -1 (from --set)"),
                std::string::npos)
          << error.what();
    }
  }
}

TEST(OverrideOption, IndexIntoSomethingNotAList) {
  const InputError scalar = error_with({"tool.diameter.0=3"});
  EXPECT_EQ(scalar.field(), "tool.diameter");
  EXPECT_NE(std::string(scalar.what())
                .find("needs tool.diameter to be a list or a section, but it is the value '10' "
                      "(from --set)"),
            std::string::npos)
      << scalar.what();
  const InputError map = error_with({"process[0]=3"});
  EXPECT_EQ(map.field(), "process");
  EXPECT_NE(std::string(map.what()).find("indexes process, which is a map, not a list"),
            std::string::npos)
      << map.what();
  // Inside a list entry: the entry is a map, its fields are values.
  const InputError inner = error_with({"dynamics.modes.0.fn.0=3"});
  EXPECT_EQ(inner.field(), "dynamics.modes[0].fn");
  EXPECT_NE(std::string(inner.what()).find("the value '100'"), std::string::npos) << inner.what();
}

TEST(OverrideOption, IndexIntoAListTheJobLacks) {
  const char* no_dynamics = "tool: {diameter: 10, teeth: 2}\n";
  for (const char* path : {"dynamics.modes.0.zeta", "dynamics.modes[0].zeta"}) {
    try {
      parse_job(no_dynamics, "job.yaml", {Override{path, "2%"}});
      ADD_FAILURE() << "accepted " << path;
    } catch (const InputError& error) {
      EXPECT_EQ(error.field(), "dynamics.modes") << path;
      EXPECT_EQ(error.line(), 0);
      EXPECT_NE(std::string(error.what())
                    .find("the job has no dynamics.modes list to index; give the whole list "
                          "instead, such as --set 'dynamics.modes=[...]' (from --set)"),
                std::string::npos)
          << error.what();
    }
  }
  // A list of values the job lacks, too (robot.posture), and no map is left
  // behind: the whole list form works.
  const InputError posture = error_with({"robot.posture.0=30"});
  EXPECT_EQ(posture.field(), "robot.posture");
  EXPECT_NE(std::string(posture.what()).find("the job has no robot.posture list"),
            std::string::npos)
      << posture.what();
}

TEST(OverrideOption, ANumberAfterAMapIsAKey) {
  // toolpath.bases is keyed by KRL base numbers: `1` names base 1, whether
  // the map is in the job or created by --set.
  const std::filesystem::path krl =
      std::filesystem::path(ROBOMILL_SOURCE_DIR) / "examples" / "toolpath_pocket_krl.yaml";
  const Job job =
      robomill::job::load_job(krl, {parse_override("toolpath.bases.1=[10, 0, 0, 0, 0, 0]"),
                                    parse_override("toolpath.bases.2=[0, 5, 0, 0, 0, 0]")});
  ASSERT_TRUE(job.toolpath.has_value());
  ASSERT_EQ(job.toolpath->bases.size(), 2u);
  EXPECT_NEAR(job.toolpath->bases.at(1).translation().x(), 0.010, 1e-12);
  EXPECT_NEAR(job.toolpath->bases.at(2).translation().y(), 0.005, 1e-12);
}

TEST(OverrideOption, ErrorsInIndexedFieldsSayFromSet) {
  // Dotted and bracket forms mark the same field as coming from --set.
  for (const char* assignment : {"dynamics.modes.0.zeta=abc", "dynamics.modes[0].zeta=abc"}) {
    const InputError error = error_with({assignment});
    EXPECT_EQ(error.field(), "dynamics.modes[0].zeta") << assignment;
    EXPECT_EQ(error.line(), 0) << assignment;
    EXPECT_TRUE(from_set(error)) << error.what();
  }
  EXPECT_STREQ(error_with({"dynamics.modes.0.zeta=abc"}).what(),
               error_with({"dynamics.modes[0].zeta=abc"}).what());
  const InputError second = error_with({"dynamics.modes.0.zeta=0.5%", "dynamics.modes.1.k=0"});
  EXPECT_EQ(second.field(), "dynamics.modes[1].k");
  EXPECT_EQ(second.line(), 0);
  EXPECT_TRUE(from_set(second)) << second.what();
  // A field not overridden keeps its file line.
  const InputError untouched = error_with({"dynamics.modes.0.zeta=1%", "tool.diameter=1.5"});
  EXPECT_EQ(untouched.field(), "process.ae");
  EXPECT_EQ(untouched.line(), 8);
}

// --- every list of the schema ------------------------------------------------

// One list of the job schema: a job that has it (an example, plus overrides
// that add the list where no example has it), an override of its first entry
// (or a field of it) in the dotted form, and what the parsed job must show.
struct ListCase {
  std::string field;               // schema path: "dynamics.modes[].shape"
  std::string example;             // file in examples/
  std::vector<std::string> setup;  // `path=value` overrides applied first
  std::string assignment;          // the dotted override of entry 0
  std::function<void(const Job&)> check;
};

std::vector<ListCase> list_cases() {
  // clang-format off
  return {
    {"experiments", "003_kr270_process_damping.yaml", {}, "experiments.0.depth=0.3 mm",
     [](const Job& j) { EXPECT_NEAR(j.experiments.at(0).axial_depth_m, 3e-4, 1e-15); }},
    {"experiments[].posture", "learn/kr270_robot.yaml", {}, "experiments.0.posture.0=5 deg",
     [](const Job& j) { EXPECT_NEAR(j.experiments.at(0).posture_rad.at(0), 5.0 * std::numbers::pi / 180.0, 1e-15); }},
    {"experiments[].position", "learn/kr270_robot.yaml",
     {"experiments=[{spindle: 3000 rpm, depth: 1 mm, chatter: false, position: [300, 300, 100]}]"},
     "experiments.0.position.1=250 mm",
     [](const Job& j) { EXPECT_NEAR(j.experiments.at(0).position_m->y(), 0.25, 1e-15); }},
    {"learn.places", "learn/kr270_robot.yaml", {}, "learn.places.0.posture=[1, 20, 20, 0, 50, 0]",
     [](const Job& j) { EXPECT_NEAR(j.learn->places_rad.at(0).at(0), std::numbers::pi / 180.0, 1e-15); }},
    {"learn.places[].posture", "learn/kr270_robot.yaml", {}, "learn.places.0.posture.1=25 deg",
     [](const Job& j) { EXPECT_NEAR(j.learn->places_rad.at(0).at(1), 25.0 * std::numbers::pi / 180.0, 1e-15); }},
    {"dynamics.modes", "demo.yaml", {}, "dynamics.modes.0.zeta=2 %",
     [](const Job& j) { EXPECT_NEAR(j.modes.at(0).damping_ratio, 0.02, 1e-15); }},
    // dynamics.frf is a list or a map by direction; this is the list form.
    {"dynamics.frf", "000_kr600_multipoint.yaml", {}, "dynamics.frf.0={file: data/003_kr270_tab1.uff}",
     [](const Job& j) { EXPECT_EQ(j.frf_files.at(0).file.filename().string(), "003_kr270_tab1.uff"); }},
    {"dynamics.at", "001_kr270_posture_library.yaml",
     {"dynamics.at=[-9.593, 22.56, 18.463, 0, 48.977, -9.593]"}, "dynamics.at.0=-10",
     [](const Job& j) { EXPECT_NEAR(j.posture_library->query_rad[0], -10 * kDeg, 1e-12); }},
    // A mode's direction is a word or a vector; this is the vector form.
    {"dynamics.modes[].direction", "demo.yaml", {"dynamics.modes.0.direction=[0, 1, 0]"},
     "dynamics.modes.0.direction.0=1",
     [](const Job& j) {
       EXPECT_NEAR(j.modes.at(0).direction_vector.x(), std::sqrt(0.5), 1e-12);
       EXPECT_NEAR(j.modes.at(0).direction_vector.y(), std::sqrt(0.5), 1e-12);
     }},
    {"dynamics.modes[].shape", "000_kr600_multipoint.yaml", {}, "dynamics.modes.0.shape.0.value=3.3",
     [](const Job& j) { EXPECT_DOUBLE_EQ(j.modes.at(0).shape.values().at(0), 3.3); }},
    {"dynamics.fit.bands", "003_kr270_measured_frf.yaml",
     {"dynamics.fit.bands=[{from: 10 Hz, to: 100 Hz}, {from: 100 Hz, to: 6000 Hz}]"},
     "dynamics.fit.bands.0.to=90 Hz",
     [](const Job& j) { EXPECT_DOUBLE_EQ(j.fit.bands.at(0).high_hz, 90.0); }},
    {"dynamics.postures", "001_kr270_posture_library.yaml", {},
     "dynamics.postures.0.posture=[-23, 12.909, 32.506, 0, 44.585, -23.199]",
     [](const Job& j) { EXPECT_NEAR(j.posture_library->postures_rad.at(0)[0], -23 * kDeg, 1e-12); }},
    {"dynamics.postures[].posture", "001_kr270_posture_library.yaml", {}, "dynamics.postures.0.posture.5=-23",
     [](const Job& j) { EXPECT_NEAR(j.posture_library->postures_rad.at(0)[5], -23 * kDeg, 1e-12); }},
    {"dynamics.postures[].modes", "001_kr270_posture_library.yaml", {}, "dynamics.postures.0.modes.0.zeta=3 %",
     [](const Job& j) {
       EXPECT_NEAR(j.posture_library->tables.at(0).at(0).damping_ratio, 0.03, 1e-15);
       EXPECT_NEAR(j.posture_library->tables.at(1).at(0).damping_ratio, 0.02, 1e-15);
     }},
    {"dynamics.idw.joint_weights", "001_kr270_posture_library.yaml",
     {"dynamics.idw.joint_weights=[1, 1, 1, 1, 1, 1]"}, "dynamics.idw.joint_weights.0=2",
     [](const Job& j) { EXPECT_DOUBLE_EQ(j.posture_library->idw.joint_weights[0], 2.0); }},
    {"robot.dh", "001_kr270_posture_library.yaml", {}, "robot.dh.0.a=360 mm",
     [](const Job& j) { EXPECT_NEAR(j.robot->description.dh->rows.at(0).a_m, 0.36, 1e-15); }},
    {"robot.joint_stiffness", "001_kr270_posture_library.yaml", {}, "robot.joint_stiffness.0=1.2e7",
     [](const Job& j) { EXPECT_DOUBLE_EQ(j.robot->description.joints.at(0).stiffness_nm_per_rad, 1.2e7); }},
    {"robot.joints", "001_kr270_posture_library.yaml", {}, "robot.joints.0.lower=-170 deg",
     [](const Job& j) { EXPECT_NEAR(j.robot->description.joints.at(0).lower_rad, -170 * kDeg, 1e-12); }},
    {"robot.links", "001_kr270_posture_library.yaml", {}, "robot.links.0.mass=410 kg",
     [](const Job& j) { EXPECT_DOUBLE_EQ(j.robot->description.dh->links.at(0).mass_kg, 410.0); }},
    {"robot.links[].cog", "001_kr270_posture_library.yaml", {}, "robot.links.0.cog.0=-170",
     [](const Job& j) { EXPECT_NEAR(j.robot->description.dh->links.at(0).center_of_mass_m.x(), -0.17, 1e-15); }},
    {"robot.links[].inertia", "001_kr270_posture_library.yaml", {}, "robot.links.0.inertia.0=41",
     [](const Job& j) { EXPECT_DOUBLE_EQ(j.robot->description.dh->links.at(0).inertia_kg_m2(0, 0), 41.0); }},
    {"robot.base.xyz", "001_kr270_posture_library.yaml", {"robot.base={xyz: [0, 0, 0], rpy: [0, 0, 0]}"},
     "robot.base.xyz.0=100",
     [](const Job& j) { EXPECT_NEAR(j.robot->description.base.translation().x(), 0.1, 1e-15); }},
    {"robot.base.rpy", "001_kr270_posture_library.yaml", {"robot.base={xyz: [0, 0, 0], rpy: [0, 0, 0]}"},
     "robot.base.rpy.0=90",
     [](const Job& j) { EXPECT_NEAR(j.robot->description.base.linear()(2, 1), 1.0, 1e-12); }},
    {"robot.tool.xyz", "001_kr270_posture_library.yaml", {}, "robot.tool.xyz.0=10",
     [](const Job& j) { EXPECT_NEAR(j.robot->description.flange_to_tool.translation().x(), 0.01, 1e-15); }},
    {"robot.tool.rpy", "001_kr270_posture_library.yaml", {}, "robot.tool.rpy.0=90",
     [](const Job& j) { EXPECT_NEAR(j.robot->description.flange_to_tool.linear()(2, 1), 1.0, 1e-12); }},
    {"robot.posture", "001_kr270_posture_library.yaml", {}, "robot.posture.0=-9",
     [](const Job& j) { EXPECT_NEAR(j.robot->posture_rad.at(0), -9 * kDeg, 1e-12); }},
    {"robot.map.from", "001_kr270_posture_library.yaml", {}, "robot.map.from.0=1500",
     [](const Job& j) { EXPECT_NEAR(j.robot->map->from_m.x(), 1.5, 1e-15); }},
    {"robot.map.to", "001_kr270_posture_library.yaml", {}, "robot.map.to.0=2300",
     [](const Job& j) { EXPECT_NEAR(j.robot->map->to_m.x(), 2.3, 1e-15); }},
    {"robot.map.counts", "001_kr270_posture_library.yaml", {}, "robot.map.counts.0=3",
     [](const Job& j) { EXPECT_EQ(j.robot->map->counts[0], 3); }},
    {"robot.map.tool_axis", "001_kr270_posture_library.yaml", {}, "robot.map.tool_axis.1=1",
     [](const Job& j) { EXPECT_NEAR(j.robot->map->tool_axis.y(), std::sqrt(0.5), 1e-12); }},
    {"robot.map.feed", "001_kr270_posture_library.yaml", {}, "robot.map.feed.1=1",
     [](const Job& j) { EXPECT_NEAR(j.robot->map->feed.y(), std::sqrt(0.5), 1e-12); }},
    {"output.formats", "demo.yaml", {"output.formats=[csv, json]"}, "output.formats.0=html",
     [](const Job& j) {
       EXPECT_TRUE(j.output.html);
       EXPECT_FALSE(j.output.csv);
       EXPECT_TRUE(j.output.json);
     }},
    {"workpiece.table", "004_kr300_pose_optimization.yaml", {}, "workpiece.table.0=610",
     [](const Job& j) { EXPECT_NEAR(j.workpiece->cell.table_origin_m.x(), 0.61, 1e-15); }},
    {"path.start", "004_kr300_pose_optimization.yaml", {}, "path.start.0=130",
     [](const Job& j) { EXPECT_NEAR(j.path.at(0).position_m.x(), 0.13, 1e-15); }},
    {"optimize.variables", "004_kr300_pose_optimization.yaml", {"optimize.variables=[x, y]"},
     "optimize.variables.0=theta",
     [](const Job& j) {
       EXPECT_FALSE(j.optimize->bounds.free[0]);
       EXPECT_TRUE(j.optimize->bounds.free[1]);
       EXPECT_TRUE(j.optimize->bounds.free[2]);
     }},
    {"optimize.poses", "004_kr300_pose_optimization.yaml", {}, "optimize.poses.0.x=610",
     [](const Job& j) { EXPECT_NEAR(j.optimize->poses.at(0).x_m, 0.61, 1e-15); }},
    {"optimize.bounds.x", "004_kr300_pose_optimization.yaml", {}, "optimize.bounds.x.0=10",
     [](const Job& j) { EXPECT_NEAR(j.optimize->bounds.lower.x_m, 0.01, 1e-15); }},
    {"optimize.bounds.y", "004_kr300_pose_optimization.yaml", {}, "optimize.bounds.y.0=-400",
     [](const Job& j) { EXPECT_NEAR(j.optimize->bounds.lower.y_m, -0.4, 1e-15); }},
    {"optimize.bounds.theta", "004_kr300_pose_optimization.yaml", {}, "optimize.bounds.theta.0=5",
     [](const Job& j) { EXPECT_NEAR(j.optimize->bounds.lower.theta_rad, 5 * kDeg, 1e-12); }},
    {"optimize.landscape.theta", "004_kr300_pose_optimization.yaml", {}, "optimize.landscape.theta.0=5",
     [](const Job& j) { EXPECT_NEAR(j.optimize->landscape_theta_rad.at(0), 5 * kDeg, 1e-12); }},
    {"toolpath.origin", "toolpath_pocket_gcode.yaml", {}, "toolpath.origin.0=5",
     [](const Job& j) { EXPECT_NEAR(j.toolpath->program_to_workpiece.translation().x(), 0.005, 1e-15); }},
    {"toolpath.orientation", "toolpath_ball_5axis_apt.yaml", {}, "toolpath.orientation.0=90",
     [](const Job& j) { EXPECT_NEAR(j.toolpath->program_to_workpiece.linear()(1, 0), 1.0, 1e-12); }},
    {"stock.box.min", "toolpath_pocket_gcode.yaml", {}, "stock.box.min.0=-1",
     [](const Job& j) { EXPECT_NEAR(j.stock->min_m.x(), -0.001, 1e-15); }},
    {"stock.box.max", "toolpath_pocket_gcode.yaml", {}, "stock.box.max.0=61",
     [](const Job& j) { EXPECT_NEAR(j.stock->max_m.x(), 0.061, 1e-15); }},
    {"uncertainty.variables", "uncertainty_stability.yaml", {}, "uncertainty.variables.0.sigma=0.3",
     [](const Job& j) {
       const auto& p = std::get<robomill::uncertainty::Lognormal>(*j.uncertainty->variables.at(0).distribution);
       EXPECT_EQ(p.sigma, 0.3);
     }},
    {"recordings", "listen/benchmark_displacement_wav.yaml", {}, "recordings.0.depth=0.3 mm",
     [](const Job& j) { EXPECT_NEAR(*j.recordings.at(0).depth_m, 3e-4, 1e-15); }},
    {"recordings[].ignore", "listen/benchmark_displacement_wav.yaml", {"recordings.0.ignore=[100 Hz]"},
     "recordings.0.ignore.0=120 Hz",
     [](const Job& j) { EXPECT_EQ(j.recordings.at(0).ignore.at(0).frequency_hz, 120.0); }},
    {"recording.ignore", "listen/benchmark_sound_wav.yaml", {"recording.ignore=[100 Hz]"},
     "recording.ignore.0=120 Hz",
     [](const Job& j) { EXPECT_EQ(j.recordings.at(0).ignore.at(0).frequency_hz, 120.0); }},
    {"listen.band", "listen/benchmark_sound_wav.yaml", {"listen.band=[10 Hz, 5 kHz]"},
     "listen.band.0=20 Hz", [](const Job& j) { EXPECT_EQ(j.listen->detector.band_low_hz, 20.0); }},
    {"listen.spindle_range", "listen/benchmark_displacement_wav.yaml", {},
     "listen.spindle_range.0=9000 rpm",
     [](const Job& j) { EXPECT_NEAR(j.listen->spindle_range_rad_s->first, 300.0 * std::numbers::pi, 1e-9); }},
    {"surface.area", "001_case_1_surface.yaml", {}, "surface.area.0=1.5",
     [](const Job& j) { EXPECT_NEAR(j.surface->area_x_m, 0.0015, 1e-15); }},
    {"surface.grid", "001_case_1_surface.yaml", {}, "surface.grid.0=120",
     [](const Job& j) { EXPECT_EQ(j.surface->cells_x, 120); }},
    {"surface.origin", "001_case_1_surface.yaml", {"surface.origin=[0, 0]"}, "surface.origin.0=0.5",
     [](const Job& j) { EXPECT_NEAR(j.surface->origin_x_m, 0.0005, 1e-15); }},
    {"simulation.fixation.mass", "002_case_c_2dof.yaml", {}, "simulation.fixation.mass.0=90 kg",
     [](const Job& j) { EXPECT_DOUBLE_EQ(j.simulation->mass_kg(0, 0), 90.0); }},
    {"simulation.fixation.stiffness", "002_case_c_2dof.yaml", {}, "simulation.fixation.stiffness.0=4e5",
     [](const Job& j) { EXPECT_DOUBLE_EQ(j.simulation->stiffness_n_per_m(0, 0), 4e5); }},
    {"simulation.fixation.damping", "002_case_c_2dof.yaml", {}, "simulation.fixation.damping.0=500",
     [](const Job& j) { EXPECT_DOUBLE_EQ(j.simulation->damping_n_s_per_m(0, 0), 500.0); }},
    {"atlas.tool_axis", "003_kr270_atlas.yaml", {}, "atlas.tool_axis.1=1",
     [](const Job& j) { EXPECT_NEAR(j.atlas->tool_axis.y(), std::sqrt(0.5), 1e-12); }},
    {"atlas.feed", "003_kr270_atlas.yaml", {}, "atlas.feed.1=1",
     [](const Job& j) { EXPECT_NEAR(j.atlas->feed.y(), std::sqrt(0.5), 1e-12); }},
    {"atlas.analyses", "003_kr270_atlas.yaml", {}, "atlas.analyses.0=frequency",
     [](const Job& j) {
       EXPECT_FALSE(j.atlas->compliance);
       EXPECT_TRUE(j.atlas->frequency);
       EXPECT_TRUE(j.atlas->stability);
     }},
    {"atlas.grid.from", "003_kr270_atlas.yaml", {}, "atlas.grid.from.0=1500",
     [](const Job& j) { EXPECT_NEAR(j.atlas->from_m.x(), 1.5, 1e-15); }},
    {"atlas.grid.to", "003_kr270_atlas.yaml", {}, "atlas.grid.to.0=2100",
     [](const Job& j) { EXPECT_NEAR(j.atlas->to_m.x(), 2.1, 1e-15); }},
    {"atlas.grid.counts", "003_kr270_atlas.yaml", {}, "atlas.grid.counts.0=4",
     [](const Job& j) { EXPECT_EQ(j.atlas->counts[0], 4); }},
  };
  // clang-format on
}

// "dynamics.modes[].shape" → "dynamics.modes.0.shape" (`dotted`) or
// "dynamics.modes[0].shape".
std::string concrete(std::string_view schema_path, bool dotted) {
  std::string out;
  for (std::size_t i = 0; i < schema_path.size(); ++i) {
    if (schema_path.substr(i, 2) == "[]") {
      out += dotted ? ".0" : "[0]";
      ++i;
    } else {
      out += schema_path[i];
    }
  }
  return out;
}

std::vector<Override> overrides_of(const std::vector<std::string>& assignments) {
  std::vector<Override> overrides;
  for (const std::string& assignment : assignments)
    overrides.push_back(parse_override(assignment));
  return overrides;
}

TEST(OverrideOption, EveryListInTheSchemaTakesIndices) {
  // The schema's list-valued fields: lists of maps and of values. Two
  // variants have a list form (dynamics.frf: a list or a map by direction; a
  // mode's direction: a word or a vector); the other variants
  // (dynamics.frf.x|y|z: a path or a map, atlas.redundancy: an angle or a
  // map) have none.
  std::set<std::string> lists;
  for (const schema::Field& f : schema::fields()) {
    using K = schema::Kind;
    if (f.kind == K::list || f.kind == K::quantities || f.kind == K::integers ||
        f.kind == K::choices) {
      lists.insert(schema::path(f));
    }
  }
  lists.insert("dynamics.frf");
  lists.insert("dynamics.modes[].direction");
  std::set<std::string> covered;
  const std::filesystem::path examples = std::filesystem::path(ROBOMILL_SOURCE_DIR) / "examples";
  for (const ListCase& c : list_cases()) {
    SCOPED_TRACE(c.field + " in " + c.example);
    EXPECT_TRUE(covered.insert(c.field).second) << "listed twice";
    EXPECT_TRUE(lists.count(c.field)) << "not a list of the schema";
    const std::filesystem::path file = examples / c.example;

    // The dotted override of entry 0 reaches the parsed job.
    std::vector<std::string> assignments = c.setup;
    assignments.push_back(c.assignment);
    try {
      c.check(robomill::job::load_job(file, overrides_of(assignments)));
    } catch (const InputError& e) {
      ADD_FAILURE() << e.what();
    }

    // A wrong entry 0 is reported at that entry, as coming from --set, the
    // same in both forms.
    const schema::Field* field = nullptr;
    for (const schema::Field& f : schema::fields()) {
      if (schema::path(f) == c.field)
        field = &f;
    }
    ASSERT_NE(field, nullptr);
    const bool of_maps = field->kind == schema::Kind::list || c.field == "dynamics.frf";
    const std::string wrong = of_maps ? "[1, 2]" : "{a: 1}";  // a list for a map, a map for a value
    std::string messages[2];
    for (const bool dotted : {true, false}) {
      const std::string list = concrete(c.field, dotted);
      std::vector<std::string> bad = c.setup;
      bad.push_back(list + (dotted ? ".0" : "[0]") + "=" + wrong);
      try {
        robomill::job::load_job(file, overrides_of(bad));
        ADD_FAILURE() << bad.back() << " accepted";
      } catch (const InputError& e) {
        const std::string entry = concrete(c.field, false) + "[0]";
        EXPECT_EQ(e.field().substr(0, entry.size()), entry) << e.what();
        EXPECT_EQ(e.line(), 0) << e.what();
        EXPECT_TRUE(from_set(e)) << e.what();
        messages[dotted ? 0 : 1] = e.what();
      }
    }
    EXPECT_EQ(messages[0], messages[1]);
  }
  std::string missing;
  for (const std::string& list : lists) {
    if (!covered.count(list))
      missing += " " + list;
  }
  EXPECT_TRUE(missing.empty()) << "lists of the schema without a case:" << missing;
}

}  // namespace

}  // namespace test_overrides_cpp
