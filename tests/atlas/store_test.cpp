// The atlas store (atlas/store.hpp) and items (atlas/atlas.hpp): round trip,
// resume after a partial run, a different job refused, a corrupt file refused
// without being touched, and per-item results independent of the order.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "robomill/atlas/atlas.hpp"
#include "robomill/atlas/store.hpp"
#include "robomill/job/job.hpp"
#include "robomill/robot/robot_model.hpp"

namespace robomill::atlas {
namespace store_test_cpp {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("robomill_atlas_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path file = dir / name;
  for (const char* suffix : {"", "-wal", "-shm", "-journal"})
    fs::remove(file.string() + suffix);
  return file;
}

AtlasSpec small_spec() {
  AtlasSpec spec;
  spec.from_m = {1.4, -0.6, 0.6};
  spec.to_m = {2.2, 0.6, 0.6};
  spec.counts = {3, 2, 1};
  spec.redundancy_rad = {-0.5, 0.5};
  return spec;
}

StoreIdentity identity(const std::string& text) {
  StoreIdentity id;
  id.job_text = text;
  id.job_hash = fnv1a_hex(text);
  id.dof = 6;
  return id;
}

AtlasResult fake_result(std::int64_t id) {
  AtlasResult r;
  r.reachable = id % 3 != 0;
  r.lowest_frequency_hz = 10.0 + id;
  r.compliance_feed_m_per_n = 1e-7 * (id + 1);
  r.condition_number = 1.0 / 3.0 + id;
  r.depth_min_m = 1e-4 * (id + 1);
  r.depth_max_m = 2e-3;
  if (r.reachable) {
    r.q = Eigen::VectorXd::LinSpaced(6, 0.1, 0.6) * static_cast<double>(id);
  }
  return r;
}

TEST(AtlasItems, IdsEnumerateGridTimesAnglesWithRedundancyFastest) {
  const AtlasSpec spec = small_spec();
  ASSERT_EQ(item_count(spec), 12);
  const AtlasItem a = item(spec, 0), b = item(spec, 1), c = item(spec, 2), last = item(spec, 11);
  EXPECT_DOUBLE_EQ(a.redundancy_rad, -0.5);
  EXPECT_DOUBLE_EQ(b.redundancy_rad, 0.5);
  EXPECT_EQ(a.position_m, b.position_m);
  EXPECT_DOUBLE_EQ(c.position_m.x(), 1.8);  // second x of three
  EXPECT_DOUBLE_EQ(last.position_m.x(), 2.2);
  EXPECT_DOUBLE_EQ(last.position_m.y(), 0.6);
  EXPECT_THROW(item(spec, 12), std::out_of_range);
}

TEST(AtlasItems, PackUnpackIsExact) {
  const AtlasResult r = fake_result(5);
  std::vector<double> buffer(static_cast<std::size_t>(packed_size(6)));
  pack(r, 6, buffer.data());
  const AtlasResult back = unpack(buffer.data(), 6);
  EXPECT_EQ(back.reachable, r.reachable);
  EXPECT_EQ(back.condition_number, r.condition_number);
  EXPECT_EQ(back.depth_min_m, r.depth_min_m);
  EXPECT_EQ(back.q, r.q);
}

TEST(AtlasStore, RoundTripAndResumeAfterPartialRun) {
  const fs::path file = scratch("roundtrip.sqlite");
  const AtlasSpec spec = small_spec();
  {
    AtlasStore store(file, identity("job A"), spec, false);
    EXPECT_EQ(store.item_total(), 12);
    EXPECT_EQ(store.pending().size(), 12u);
    store.commit({{3, fake_result(3)}, {7, fake_result(7)}});
  }  // closed as a killed run would leave it between batches
  {
    AtlasStore store(file, identity("job A"), spec, false);
    const std::vector<std::int64_t> pending = store.pending();
    ASSERT_EQ(pending.size(), 10u);
    EXPECT_EQ(std::count(pending.begin(), pending.end(), 3), 0);
    EXPECT_EQ(std::count(pending.begin(), pending.end(), 7), 0);
    const std::vector<StoredItem> done = store.finished();
    ASSERT_EQ(done.size(), 2u);
    EXPECT_EQ(done[1].item.id, 7);
    EXPECT_EQ(done[1].item.position_m, item(spec, 7).position_m);
    const AtlasResult expected = fake_result(7);
    EXPECT_EQ(done[1].result.reachable, expected.reachable);
    EXPECT_EQ(done[1].result.condition_number, expected.condition_number);  // bit-exact
    EXPECT_EQ(done[1].result.q, expected.q);
    EXPECT_FALSE(done[0].result.reachable);  // id 3: no posture stored
    EXPECT_EQ(done[0].result.q.size(), 0);
    // A result is written once: committing an item again is an error.
    EXPECT_THROW(store.commit({{3, fake_result(3)}}), StoreError);
  }
  {
    AtlasStore reader(file, identity("job A"));  // the export path
    EXPECT_EQ(reader.finished().size(), 2u);
  }
}

TEST(AtlasStore, AnotherJobIsRefusedUnlessRestarted) {
  const fs::path file = scratch("mismatch.sqlite");
  const AtlasSpec spec = small_spec();
  {
    AtlasStore store(file, identity("job A"), spec, false);
    store.commit({{0, fake_result(0)}});
  }
  try {
    AtlasStore store(file, identity("job B"), spec, false);
    FAIL() << "a store of another job was accepted";
  } catch (const StoreMismatch& e) {
    EXPECT_NE(std::string(e.what()).find("--restart"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
  }
  EXPECT_THROW(AtlasStore(file, identity("job B")), StoreMismatch);
  {
    AtlasStore store(file, identity("job B"), spec, true);
    EXPECT_EQ(store.pending().size(), 12u);  // started over
  }
  AtlasStore again(file, identity("job B"), spec, false);
  EXPECT_EQ(again.pending().size(), 12u);
}

TEST(AtlasStore, CorruptOrForeignFileIsAnErrorAndLeftAlone) {
  const fs::path file = scratch("corrupt.sqlite");
  const std::string junk(4096, 'x');
  std::ofstream(file) << junk;
  try {
    AtlasStore store(file, identity("job A"), small_spec(), true);
    FAIL() << "a corrupt file was opened";
  } catch (const StoreError& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
  }
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), junk);
  EXPECT_THROW(AtlasStore(scratch("absent.sqlite"), identity("job A")), StoreError);
}

TEST(AtlasContext, ResultsDoNotDependOnOrder) {
  const job::Job job =
      job::load_job(fs::path(ROBOMILL_SOURCE_DIR) / "examples" / "003_kr270_atlas.yaml");
  ASSERT_TRUE(job.atlas);
  AtlasSpec spec = *job.atlas;
  spec.speed_count = 12;
  const robot::RobotModel model(job.robot->description);
  const Eigen::VectorXd seed =
      Eigen::Map<const Eigen::VectorXd>(job.robot->posture_rad.data(), model.dof());
  const AtlasContext context(spec, model, seed, tool::Tool(*job.tool), job.cutting, job.process);
  const AtlasResult forward = context.evaluate(item(spec, 4));
  (void)context.evaluate(item(spec, 40));  // another posture in between
  const AtlasResult again = context.evaluate(item(spec, 4));
  ASSERT_TRUE(forward.reachable);
  EXPECT_EQ(forward.q, again.q);
  EXPECT_EQ(forward.depth_min_m, again.depth_min_m);
  EXPECT_EQ(forward.lowest_frequency_hz, again.lowest_frequency_hz);
  EXPECT_GT(forward.depth_min_m, 0.0);
  EXPECT_GE(forward.depth_max_m, forward.depth_min_m);
  EXPECT_LE(forward.depth_max_m, spec.depth_max_m);
  EXPECT_GT(forward.compliance_feed_m_per_n, 0.0);
  // Out of reach (5 m in front of a 2.9 m robot): not reachable, zeros.
  AtlasItem far = item(spec, 0);
  far.position_m.x() = 5.0;
  const AtlasResult unreachable = context.evaluate(far);
  EXPECT_FALSE(unreachable.reachable);
  EXPECT_EQ(unreachable.depth_min_m, 0.0);
}

}  // namespace
}  // namespace store_test_cpp
}  // namespace robomill::atlas
