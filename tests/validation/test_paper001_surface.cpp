// Paper 001 (surface topography in robotic ball-end milling): the nine
// Table 2 cases through `robomill surface`'s computation, Ra and Rq next to
// Table 3, and the posture dependence of areas A-C (001 Eq 16-18 via the
// KR270-class posture library). Every assumption is in the example files
// and docs/surface.md.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string>
#include <tuple>

#include "robomill/analysis/surface_run.hpp"
#include "robomill/job/job.hpp"
#include "support/validation_record.hpp"

namespace test_paper001_surface_cpp {

namespace {

using namespace robomill;

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string example(int c) {
  return std::string(ROBOMILL_SOURCE_DIR) + "/examples/001_case_" + std::to_string(c) +
         "_surface.yaml";
}

// 001 Table 3, simulation with vibration: area -> (Ra, Rq) um; A-C case 5, D-F case 7.
struct Table3 {
  const char* area;
  int case_number;
  double ra_um, rq_um;
};
constexpr Table3 kTable3[] = {{"A", 5, 0.878, 1.103}, {"B", 5, 0.976, 1.407},
                              {"C", 5, 0.914, 1.357}, {"D", 7, 0.835, 1.187},
                              {"E", 7, 1.066, 1.527}, {"F", 7, 0.938, 1.465}};

/// Our values next to Table 3's for every area of case `c`, into the
/// validation report: (quantity, compared with Rq rather than Ra, ours in
/// um). Asserted within the "order of" (a factor of 3) when
/// `asserted`.
void record_table3(int c, const std::string& assumptions_after_file,
                   std::initializer_list<std::tuple<const char*, bool, double>> rows,
                   bool asserted) {
  for (const Table3& t : kTable3) {
    if (t.case_number != c)
      continue;
    const std::string item =
        "Tab. 3, area " + std::string(t.area) + " (case " + std::to_string(c) + ")";
    for (const auto& [quantity, against_rq, ours_um] : rows) {
      const double paper_um = against_rq ? t.rq_um : t.ra_um;
      const double ratio = ours_um / paper_um;
      const bool within = ratio > 1.0 / 3.0 && ratio < 3.0;
      if (asserted) {
        EXPECT_TRUE(within) << item << " " << quantity << ": ours " << ours_um << " um, paper "
                            << paper_um << " um";
      }
      test::record_validation({"001", item, quantity, "um", test::sig4(paper_um),
                               test::sig4(ours_um), test::labelled("x", ratio), "x1/3 ... x3",
                               within,
                               "examples/001_case_" + std::to_string(c) + assumptions_after_file});
    }
  }
}

/// The nine Table 2 cases on the paper's 100 x 100 grid, which satisfies
/// 001 Eq 29 under our reading of Table 2's feed (3000 mm/min, see the
/// examples); cases 5 and 7 next to Table 3.
TEST(Paper001Surface, Table2CasesNextToTable3) {
  for (int c = 1; c <= 9; ++c) {
    const analysis::SurfaceRun run = analysis::run_surface_job(job::load_job(example(c)), 0);
    const surface::ZMapGrid& grid = run.zmap.map.grid;
    EXPECT_LE(std::max(grid.dx(), grid.dy()), run.rules.max_cell_m * (1.0 + 1e-9))
        << "case " << c << ": the paper's grid within Eq 29";
    const double ra = run.roughness.stepover.ra_m * 1e6, rq = run.roughness.stepover.rq_m * 1e6;
    EXPECT_GT(ra, 0.0);
    EXPECT_GE(rq, ra);
    EXPECT_FALSE(run.vibration->verdict.chatter) << "case " << c << " (001 §3.2: stable cuts)";
    std::printf(
        "[validation] 001 case %d (100x100 grid, vibration): Ra %.3f um, Rq %.3f um (along the "
        "feed %.3f, %.3f), Sa %.3f um, Sz %.3f um, texture interval %.2f fz\n",
        c, ra, rq, run.roughness.feed.ra_m * 1e6, run.roughness.feed.rq_m * 1e6,
        run.roughness.sa_m * 1e6, run.roughness.sz_m * 1e6,
        run.roughness.feed_texture_interval_m / run.path.feed_per_tooth_m);
    if (c != 5 && c != 7)
      continue;
    for (const Table3& t : kTable3)
      if (t.case_number == c)
        std::printf(
            "[validation] 001 Table 3 area %s (case %d): paper Ra %.3f um, Rq %.3f um; ours Ra "
            "%.3f um, Rq %.3f um = %.2fx, %.2fx the paper (tolerance: a factor of 3)\n",
            t.area, c, t.ra_um, t.rq_um, ra, rq, ra / t.ra_um, rq / t.rq_um);
    record_table3(c,
                  ": feed 3000 mm/min (Table 2 read as in the example), the paper's 100 x 100 "
                  "grid, assumed robot modes, steady stable cut, runout angle 0, no axial "
                  "runout; the passes' phases are not aligned (Ra across the passes = along "
                  "the feed)",
                  {{"Ra across the passes", false, ra}, {"Rq across the passes", true, rq}}, true);
    // The other reading of Table 2's feed (300 mm/min, fz ten times
    // smaller) on its Eq 29 grid: the 0.1 mm scallop alone. Recorded, not
    // asserted.
    const double fz_300 = run.path.feed_per_tooth_m / 10.0;
    const int cells = static_cast<int>(std::ceil(2e-3 / (std::min(fz_300, 0.1e-3) / 5.0) - 1e-9));
    const analysis::SurfaceRun slow = analysis::run_surface_job(
        job::load_job(example(c), {{"process.feed_rate", "300 mm/min"},
                                   {"surface.grid", fmt::format("[{0}, {0}]", cells)}}),
        0);
    record_table3(
        c,
        " with feed 300 mm/min (the other reading of Table 2) on its Eq 29 grid: "
        "the 0.1 mm scallop alone; not asserted (docs/surface.md)",
        {{"Ra across the passes, feed 300 mm/min", false, slow.roughness.stepover.ra_m * 1e6}},
        false);
    // 001 §3.3: "in the feed direction, the texture interval is roughly
    // four times larger compared to the scenario without tool vibration"
    // (which is fz). Ours: fz or one revolution's feed (the runout), as
    // without vibration — the stable cut's vibration is locked to the spindle.
    const double texture_fz = run.roughness.feed_texture_interval_m / run.path.feed_per_tooth_m;
    test::record_validation(
        {"001",
         "§3.3, Fig. " + std::string(c == 5 ? "16" : "17") + " (case " + std::to_string(c) + ")",
         "texture interval along the feed with vibration", "fz", "~4", test::sig4(texture_fz),
         test::labelled("x", texture_fz / 4.0), "x0.75 ... x1.25",
         texture_fz > 3.0 && texture_fz < 5.0,
         "examples/001_case_" + std::to_string(c) +
             "_surface.yaml; the wavelength of the feed lines' largest spectral peak; 1 fz: the "
             "feed marks, 2 fz: the runout's once-per-revolution marks; not asserted"});
  }
}

/// Case 5 with the posture library's dynamics interpolated (001 Eq 16-18)
/// at three postures moving away from the robot base along x.
job::Job area_job(const char* at, const char* start) {
  const std::string case5 = read(example(5));
  const std::string library =
      read(std::string(ROBOMILL_SOURCE_DIR) + "/examples/001_kr270_posture_library.yaml");
  const std::size_t d0 = case5.find("\ndynamics:") + 1, d1 = case5.find("\nsurface:") + 1;
  const std::size_t l0 = library.find("\ndynamics:") + 1, l1 = library.find("# The robot");
  std::string dynamics = library.substr(l0, l1 - l0);
  dynamics.insert(std::string("dynamics:\n").size(), std::string("  at: ") + at + "\n");
  const std::string text = case5.substr(0, d0) + dynamics + case5.substr(d1);
  return job::parse_job(
      text, example(5),
      {{"surface.grid", "[100, 100]"}, {"surface.grid_rule", "false"}, {"surface.start", start}});
}

/// 001 §3.3 (Figures 16-17): "the residual height of the machined surface
/// tends to increase in the direction away from the robot base (from A to
/// C)". What is asserted is what the model guarantees: the interpolated
/// robot softens away from the base (lower first mode, larger static
/// deflection) and the cut stays stable, its vibration locked to the
/// spindle. The surface barely feels that — a steady vibration prints nearly
/// the same on every tooth — so the residual height (Sz) is printed and
/// recorded next to 001's trend, not asserted (docs/surface.md). 001's
/// reading of the vibration (start: rest, dde23 from a zero history) is
/// printed too.
TEST(Paper001Surface, PostureDependentVibration) {
  const char* postures[] = {"[0, 17.377, 26.257, 0, 46.366, 0]",   // tool at x = 1650 mm
                            "[0, 25.995, 13.011, 0, 50.994, 0]",   // 1900 mm
                            "[0, 34.815, -1.862, 0, 57.047, 0]"};  // 2150 mm
  const char* names[] = {"A (1650 mm)", "B (1900 mm)", "C (2150 mm)"};
  job::Job still_job = area_job(postures[0], "steady");
  still_job.surface->vibration = false;
  const analysis::SurfaceRun still = analysis::run_surface_job(still_job, 0);
  std::printf(
      "[validation] 001 case 5 without vibration: Ra %.3f um, Sa %.3f um, Sz %.3f um, max "
      "residual %.3f um\n",
      still.roughness.stepover.ra_m * 1e6, still.roughness.sa_m * 1e6, still.roughness.sz_m * 1e6,
      still.roughness.max_residual_m * 1e6);
  double sz[3] = {}, previous_hz = 1e300, previous_deflection = 0.0;
  for (int k = 0; k < 3; ++k) {
    for (const char* start : {"steady", "rest"}) {
      const analysis::SurfaceRun run = analysis::run_surface_job(area_job(postures[k], start), 0);
      const analysis::SurfaceVibration& v = *run.vibration;
      std::printf(
          "[validation] 001 case 5 area %s, IDW dynamics (first mode %.2f Hz), start: %s, "
          "static deflection y %.2f um, vibration p-p x %.2f y %.2f um, chatter %s: Ra across "
          "%.3f / along the feed %.3f um, Sa %.3f um, Sz %.3f um, max residual %.3f um\n",
          names[k], v.natural_frequencies_hz.front(), start, v.mean_m.y() * 1e6,
          v.peak_to_peak_m.x() * 1e6, v.peak_to_peak_m.y() * 1e6, v.verdict.chatter ? "yes" : "no",
          run.roughness.stepover.ra_m * 1e6, run.roughness.feed.ra_m * 1e6,
          run.roughness.sa_m * 1e6, run.roughness.sz_m * 1e6, run.roughness.max_residual_m * 1e6);
      if (std::string(start) != "steady")
        continue;
      // Farther from the base: a softer robot (001 Eq 16-18 over the library).
      EXPECT_LT(v.natural_frequencies_hz.front(), previous_hz) << names[k];
      EXPECT_GT(std::abs(v.mean_m.y()), previous_deflection) << names[k];
      previous_hz = v.natural_frequencies_hz.front();
      previous_deflection = std::abs(v.mean_m.y());
      // 001 §3.2: the cuts were chosen stable; so is ours, at every posture.
      EXPECT_FALSE(v.verdict.chatter) << names[k];
      sz[k] = run.roughness.sz_m * 1e6;
    }
  }
  test::record_validation(
      {"001", "§3.3 / Fig. 16, areas A -> C (case 5)", "residual height Sz", "um", "grows A -> C",
       test::sig4(sz[0]) + " -> " + test::sig4(sz[1]) + " -> " + test::sig4(sz[2]),
       test::labelled("x", sz[2] / sz[0]), "grows at each step; not asserted",
       sz[1] > sz[0] && sz[2] > sz[1],
       "KR270-class posture library (examples/001_kr270_posture_library.yaml) at tool x = "
       "1650, 1900, 2150 mm; 001's grid 100 x 100; steady cut, raster groove engagement; the "
       "robot softens away from the base (asserted) but a stable cut's vibration is locked to "
       "the spindle and prints nearly uniformly"});
}

}  // namespace

}  // namespace test_paper001_surface_cpp
