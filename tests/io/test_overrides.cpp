// `--set key.path=value`: syntax, application before validation, and errors
// in overridden fields reported as coming from the command line.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "robomill/core/error.hpp"
#include "robomill/io/job.hpp"

namespace {

using robomill::InputError;
using robomill::io::Job;
using robomill::io::Override;
using robomill::io::parse_job;
using robomill::io::parse_override;

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

}  // namespace
