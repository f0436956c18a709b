// The `atlas:` job section (src/job/job_parser_atlas.cpp): units converted at
// parsing, redundancy ranges expanded, the feed projected into the cutting
// plane, and bad input naming its field.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>

#include "robomill/core/error.hpp"
#include "robomill/job/job.hpp"

namespace robomill::io {
namespace job_test_cpp {
namespace {

const std::filesystem::path kExample =
    std::filesystem::path(ROBOMILL_SOURCE_DIR) / "examples" / "003_kr270_atlas.yaml";

std::string field_of(const std::vector<job::Override>& overrides) {
  try {
    job::load_job(kExample, overrides);
  } catch (const InputError& e) {
    return e.field();
  }
  return "(accepted)";
}

TEST(AtlasJob, ExampleInSiWithRedundancyRangeExpanded) {
  const job::Job job = job::load_job(kExample);
  ASSERT_TRUE(job.atlas);
  const atlas::AtlasSpec& a = *job.atlas;
  EXPECT_DOUBLE_EQ(a.from_m.x(), 1.4);
  EXPECT_DOUBLE_EQ(a.to_m.y(), 0.6);
  EXPECT_EQ(a.counts[0], 5);
  ASSERT_EQ(a.redundancy_rad.size(), 3u);
  EXPECT_NEAR(a.redundancy_rad[0], -std::numbers::pi / 6, 1e-15);
  EXPECT_NEAR(a.redundancy_rad[1], 0.0, 1e-15);
  EXPECT_TRUE(a.compliance && a.frequency && a.stability);
  EXPECT_NEAR(a.speed_from_rad_s, 1000 * 2 * std::numbers::pi / 60, 1e-9);
  EXPECT_EQ(a.speed_count, 100);
  EXPECT_DOUBLE_EQ(a.depth_max_m, 5e-3);
  EXPECT_EQ(a.store.filename(), "003_kr270_atlas.sqlite");
  EXPECT_EQ(atlas::item_count(a), 75);
}

TEST(AtlasJob, FeedProjectedIntoTheCuttingPlane) {
  const job::Job job =
      job::load_job(kExample, {{"atlas.feed", "[1, 0, 1]"}, {"atlas.redundancy", "10"}});
  EXPECT_NEAR(job.atlas->feed.x(), 1.0, 1e-15);
  EXPECT_NEAR(job.atlas->feed.z(), 0.0, 1e-15);
  ASSERT_EQ(job.atlas->redundancy_rad.size(), 1u);
  EXPECT_NEAR(job.atlas->redundancy_rad[0], 10 * std::numbers::pi / 180, 1e-15);
}

TEST(AtlasJob, BadInputNamesTheField) {
  EXPECT_EQ(field_of({{"atlas.feed", "[0, 0, 2]"}}), "atlas.feed");
  EXPECT_EQ(field_of({{"atlas.grid.counts", "[2, 2]"}}), "atlas.grid.counts");
  EXPECT_EQ(field_of({{"atlas.analyses", "[compliance, chatter]"}}), "atlas.analyses[1]");
  EXPECT_EQ(field_of({{"atlas.redundancy", "{from: 10, to: 0, count: 3}"}}), "atlas.redundancy.to");
  EXPECT_EQ(field_of({{"atlas.analyses", "[compliance]"}}), "atlas.speeds");  // left over
  EXPECT_EQ(field_of({{"atlas.depth_max", "0 mm"}}), "atlas.depth_max");
  EXPECT_EQ(field_of({{"atlas.colour", "red"}}), "atlas.colour");
  EXPECT_EQ(field_of({{"robot.posture", "null"}}), "robot.posture");
}

}  // namespace
}  // namespace job_test_cpp
}  // namespace robomill::io
