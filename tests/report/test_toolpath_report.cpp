// report.html of `robomill toolpath`: a square pocket's output files, made
// here in the formats the command writes, give the 3-D path coloured by
// engagement and force, the loads over time with the program lines, the
// final stock, the worst moves and the warnings, with no NaN on the page.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "../../src/report/detail.hpp"
#include "robomill/report/report.hpp"

namespace rr = robomill::report;
namespace rd = robomill::report::detail;
using nlohmann::json;

namespace {

constexpr const char* kSampleHeader =
    "line,t_s,x_mm,y_mm,z_mm,axis_i,axis_j,axis_k,tool,motion,feed_mm_min,spindle_rpm,"
    "feed_per_tooth_mm,ap_mm,ae_mm,engagement_deg,entry_deg,exit_deg,arcs,section_mm2,"
    "chip_area_mm2,fx_N,fy_N,fz_N,force_mean_N,force_peak_N,torque_Nm,torque_peak_Nm,power_W,"
    "analysed,plunge\n";

struct Sample {
  int line;
  double t, x, y, z;
  const char* motion;
  double ap, ae, engagement, force;
  bool plunge;
};

std::string sample_row(const Sample& s) {
  const bool cutting = s.engagement > 0.0;
  const double rpm = 8000.0, torque = 0.004 * s.force;
  return fmt::format(
      "{},{},{},{},{},0,0,1,1,{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
      s.line, s.t, s.x, s.y, s.z, s.motion, std::string(s.motion) == "rapid" ? 20000 : 1200, rpm,
      0.05, s.ap, s.ae, s.engagement, cutting ? 180.0 - s.engagement : 0.0, cutting ? 180.0 : 0.0,
      cutting ? 1 : 0, s.ap * s.ae, 0.05 * s.ap, 0.6 * s.force, 0.7 * s.force, 0.1 * s.force,
      0.8 * s.force, s.force, torque, 1.3 * torque, torque * rpm * 2.0 * std::numbers::pi / 60.0,
      cutting ? 1 : 0, s.plunge ? 1 : 0);
}

/// A 20 mm square pocket, 5 mm deep, in a 40 × 40 × 20 mm block, milled by a
/// 10 mm cutter: rapid in (lines 1-2), plunge (3), four sides along the
/// pocket's edge (4-7, the first at full width: the largest force on line 4),
/// rapid out (8). `per_move` samples per move; line numbers offset by
/// `first_line - 1`.
std::string pocket_samples(int per_move, int first_line = 1) {
  std::string csv = kSampleHeader;
  double t = 0.0;
  auto move = [&](int line, const char* motion, double x0, double y0, double z0, double x1,
                  double y1, double z1, double ap, double ae, double engagement, double force,
                  bool plunge) {
    for (int i = 0; i < per_move; ++i) {
      const double u = static_cast<double>(i + 1) / per_move;
      t += 0.01;
      csv += sample_row({line + first_line - 1, t, x0 + u * (x1 - x0), y0 + u * (y1 - y0),
                         z0 + u * (z1 - z0), motion, ap, ae, engagement,
                         force * (0.8 + 0.2 * std::sin(7.0 * u)), plunge});
    }
  };
  move(1, "rapid", 20, 20, 40, 15, 15, 40, 0, 0, 0, 0, false);
  move(2, "rapid", 15, 15, 40, 15, 15, 22, 0, 0, 0, 0, false);
  move(3, "linear", 15, 15, 22, 15, 15, 15, 0, 0, 0, 0, true);  // plunges into air here
  move(4, "linear", 15, 15, 15, 25, 15, 15, 5, 10, 180, 800, false);
  move(5, "linear", 25, 15, 15, 25, 25, 15, 5, 5, 90, 420, false);
  move(6, "arc", 25, 25, 15, 15, 25, 15, 5, 5, 90, 430, false);
  move(7, "linear", 15, 25, 15, 15, 15, 15, 5, 5, 90, 410, false);
  move(8, "rapid", 15, 15, 15, 15, 15, 40, 0, 0, 0, 0, false);
  return csv;
}

/// The final stock as the command writes it: x fastest, then y.
std::string pocket_stock(double spacing_mm) {
  std::string csv = "x_mm,y_mm,z_mm\n";
  const int n = static_cast<int>(std::lround(40.0 / spacing_mm));
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = i * spacing_mm, y = j * spacing_mm;
      const bool pocket = x >= 10 && x <= 30 && y >= 10 && y <= 30;
      csv += fmt::format("{},{},{}\n", x, y, pocket ? 15.0 : 20.0);
    }
  return csv;
}

std::string pocket_moves() {
  std::string csv =
      "line,move,tool,motion,length_mm,time_s,feed_mm_min,spindle_rpm,samples,engaged_samples,"
      "removed_mm3,max_ap_mm,max_ae_mm,max_engagement_deg,max_force_N,max_torque_Nm,max_power_W,"
      "tool_described\n";
  struct Move {
    int line;
    const char* motion;
    double force;
  };
  const Move moves[] = {{1, "rapid", 0},       {2, "rapid", 0},    {3, "linear", 0},
                        {4, "linear", 812},    {5, "linear", 431}, {6, "arc", 440},
                        {7, "linear", 418},    {8, "rapid", 0},    {12345, "linear", 120},
                        {12346, "linear", NAN}};
  int index = 1;
  for (const Move& m : moves) {
    const bool cut = m.force > 0.0;
    csv +=
        fmt::format("{},{},1,{},10,0.5,1200,8000,40,{},{},{},{},{},{},{},{},1\n", m.line, index++,
                    m.motion, cut ? 40 : 0, cut ? 250.0 : 0.0, cut ? 5.0 : 0.0, cut ? 5.0 : 0.0,
                    cut ? 90.0 : 0.0, m.force, 0.004 * m.force, 0.004 * m.force * 838.0);
  }
  return csv;
}

json pocket_summary() {
  return {
      {"command", "toolpath"},
      {"name", "square pocket"},
      {"program", "pocket.nc"},
      {"dialect", "gcode"},
      {"moves", 8},
      {"samples", 400},
      {"engaged_samples", 160},
      {"cutting_time_s", 2.0},
      {"air_time_s", 1.2},
      {"dwell_time_s", 0.0},
      {"cycle_time_s", 3.2},
      {"volume_removed_mm3", 2000.0},
      {"max_force_N", 812.0},
      {"max_force_line", 4},
      {"max_torque_Nm", 3.25},
      {"max_torque_line", 4},
      {"max_power_W", 2722.0},
      {"max_power_line", 4},
      {"max_engagement_deg", 180.0},
      {"max_engagement_line", 4},
      {"warnings",
       json::array({{{"line", 4}, {"text", "full-width slot: peak force 812 N"}, {"count", 3}}})},
      {"notes", json::array({{{"line", 2}, {"text", "G90 assumed"}}})},
      {"stock",
       {{"min_mm", {0, 0, 0}},
        {"max_mm", {40, 40, 20}},
        {"resolution_mm", 0.5},
        {"memory_MB", 0.1}}},
      {"elapsed_s", 0.2}};
}

rr::Files pocket_files(int per_move = 50, double stock_spacing_mm = 0.5, int first_line = 1) {
  return {{"summary.json", pocket_summary().dump(2)},
          {"samples_preview.csv", pocket_samples(per_move, first_line)},
          {"moves.csv", pocket_moves()},
          {"stock.csv", pocket_stock(stock_spacing_mm)},
          {"inputs.json",
           R"({"inputs": [{"group": "program", "name": "file", "value": "pocket.nc"}]})"}};
}

rd::Content content_of(const rr::Files& files) {
  const rd::Outputs outputs{files, json::parse(files.at("summary.json")), "toolpath"};
  return rd::build_content(outputs);
}

const rd::Figure* figure_titled(const rd::Content& c, const std::string& title) {
  for (const rd::Figure& f : c.figures)
    if (f.title == title)
      return &f;
  return nullptr;
}

const rd::TextTable* table_starting(const rd::Content& c, const std::string& title) {
  for (const rd::TextTable& t : c.tables)
    if (t.title.starts_with(title))
      return &t;
  return nullptr;
}

std::size_t finite_count(const json& array) {
  std::size_t n = 0;
  for (const json& v : array)
    n += v.is_number() ? 1 : 0;
  return n;
}

}  // namespace

TEST(ToolpathReport, HasDedicatedFigures) {
  EXPECT_TRUE(rr::has_dedicated_figures("toolpath"));
}

TEST(ToolpathReport, PathIn3DColouredByEngagementWithForceOnTheMenu) {
  const rd::Content c = content_of(pocket_files());
  EXPECT_TRUE(c.notes.empty());
  const rd::Figure* path = figure_titled(c, "Tool path");
  ASSERT_NE(path, nullptr);
  ASSERT_GE(path->data.size(), 3u);
  const json& feed = path->data[0];
  EXPECT_EQ(feed["type"], "scatter3d");
  // Feed moves: 5 moves of 50 samples; the rapids in grey, apart.
  EXPECT_EQ(finite_count(feed["x"]), 250u);
  EXPECT_EQ(feed["marker"]["colorbar"]["title"]["text"], "engagement (°)");
  EXPECT_DOUBLE_EQ(feed["marker"]["cmax"].get<double>(), 180.0);
  EXPECT_NE(feed["hovertemplate"].get<std::string>().find("line %{customdata[0]}"),
            std::string::npos);
  EXPECT_EQ(feed["customdata"][0][0], 3);  // the plunge's first sample: line 3
  const json& rapids = path->data[1];
  EXPECT_EQ(rapids["name"], "rapids");
  EXPECT_EQ(rapids["line"]["color"], "#9aa3ad");
  // 150 rapid samples, each run joined to its neighbours, one gap between the runs.
  EXPECT_EQ(finite_count(rapids["x"]), 152u);
  EXPECT_EQ(rapids["x"].size(), 153u);
  const json& peak = path->data[2];
  EXPECT_EQ(peak["name"], "largest peak force");
  EXPECT_NE(peak["hovertemplate"].get<std::string>().find("line 4"), std::string::npos);
  // The menu recolours the feed moves by the peak force.
  const json& buttons = path->layout["updatemenus"][0]["buttons"];
  ASSERT_EQ(buttons.size(), 2u);
  const json& by_force = buttons[1]["args"][0];
  EXPECT_EQ(by_force["marker.colorbar.title.text"], "peak force (N)");
  EXPECT_EQ(by_force["marker.color"][0].size(), feed["x"].size());
  EXPECT_NEAR(by_force["marker.cmax"].get<double>(), 800.0, 1.0);
  EXPECT_EQ(path->layout["scene"]["aspectmode"], "data");
  EXPECT_EQ(path->layout["scene"]["zaxis"]["title"]["text"], "z (mm)");
}

TEST(ToolpathReport, LoadsOverTimeWithTheProgramLinesOnHover) {
  const rd::Content c = content_of(pocket_files());
  const rd::Figure* time = figure_titled(c, "Engagement and loads over time");
  ASSERT_NE(time, nullptr);
  std::vector<std::string> names;
  for (const json& t : time->data)
    names.push_back(t["name"]);
  for (const char* name : {"engagement", "axial depth ap", "radial depth ae", "peak force",
                           "mean force", "torque", "power", "largest peak force"})
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  for (const json& t : time->data)
    EXPECT_NE(t["hovertemplate"].get<std::string>().find("line"), std::string::npos);
  EXPECT_EQ(time->data[0]["customdata"][0], 1);
  EXPECT_EQ(time->layout["xaxis5"]["title"]["text"], "time (s)");
  EXPECT_EQ(time->layout["yaxis"]["title"]["text"], "engagement (°)");
  EXPECT_EQ(time->layout["yaxis3"]["title"]["text"], "force (N)");
  EXPECT_EQ(time->layout["yaxis4"]["title"]["text"], "torque (N·m)");
  EXPECT_EQ(time->layout["yaxis5"]["title"]["text"], "power (W)");
  // The largest peak force is marked on the force row, at line 4.
  const json& star = time->data.back();
  EXPECT_EQ(star["yaxis"], "y3");
  EXPECT_NEAR(star["y"][0].get<double>(), 800.0, 1.0);
  EXPECT_NE(time->layout["annotations"][0]["text"].get<std::string>().find("line 4"),
            std::string::npos);
}

TEST(ToolpathReport, FinalStockAsAHeightMapAndA3DSurfaceTrueToScale) {
  const rd::Content c = content_of(pocket_files());
  const rd::Figure* map = figure_titled(c, "Final stock, height map");
  ASSERT_NE(map, nullptr);
  const json& heat = map->data[0];
  EXPECT_EQ(heat["type"], "heatmap");
  ASSERT_EQ(heat["x"].size(), 81u);
  ASSERT_EQ(heat["y"].size(), 81u);
  EXPECT_DOUBLE_EQ(heat["z"][40][40].get<double>(), 15.0);  // the pocket's floor
  EXPECT_DOUBLE_EQ(heat["z"][0][0].get<double>(), 20.0);    // the block's top
  EXPECT_EQ(map->layout["yaxis"]["scaleanchor"], "x");
  const rd::Figure* surface = figure_titled(c, "Final stock, 3-D view");
  ASSERT_NE(surface, nullptr);
  EXPECT_EQ(surface->data[0]["type"], "surface");
  const json& aspect = surface->layout["scene"]["aspectratio"];
  EXPECT_DOUBLE_EQ(aspect["x"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(aspect["y"].get<double>(), 1.0);
  // 5 mm of relief over 40 mm: true to scale (1/8).
  EXPECT_DOUBLE_EQ(aspect["z"].get<double>(), 0.125);
}

TEST(ToolpathReport, WorstMovesAndWarningsAsTables) {
  const rd::Content c = content_of(pocket_files());
  const rd::TextTable* worst = table_starting(c, "The 5 moves with the largest cutting force");
  ASSERT_NE(worst, nullptr);
  ASSERT_EQ(worst->rows.size(), 5u);  // moves without force (rapids, air, NaN) are left out
  EXPECT_EQ(worst->header[0], "line");
  EXPECT_NE(std::find(worst->header.begin(), worst->header.end(), "max force (N)"),
            worst->header.end());
  EXPECT_NE(std::find(worst->header.begin(), worst->header.end(), "feed (mm/min)"),
            worst->header.end());
  EXPECT_EQ(worst->rows[0][0], "4");
  EXPECT_EQ(worst->rows[0][4], "812");
  EXPECT_EQ(worst->rows[1][0], "6");
  EXPECT_EQ(worst->rows[1][3], "arc");
  EXPECT_EQ(worst->rows[4][0], "12345");  // a line number, not 1.234e+04
  const rd::TextTable* warnings = table_starting(c, "Warnings");
  ASSERT_NE(warnings, nullptr);
  ASSERT_EQ(warnings->rows.size(), 1u);
  EXPECT_EQ(warnings->rows[0],
            (std::vector<std::string>{"4", "full-width slot: peak force 812 N", "3"}));
  const rd::TextTable* notes = table_starting(c, "Notes of the program reader");
  ASSERT_NE(notes, nullptr);
  EXPECT_EQ(notes->rows[0], (std::vector<std::string>{"2", "G90 assumed"}));
}

TEST(ToolpathReport, PageHoldsEveryPartAndNoNaN) {
  const std::string html = rr::render_html(pocket_files());
  for (const char* part :
       {"Tool path", "scatter3d", "Engagement and loads over time", "Final stock, height map",
        "heatmap", "Final stock, 3-D view", "\"surface\"", "The 5 moves with the largest",
        "full-width slot: peak force 812 N", "G90 assumed", "colour: peak force"})
    EXPECT_NE(html.find(part), std::string::npos) << part;
  const std::size_t figures = html.find("id=\"robomill-figures\"");
  ASSERT_NE(figures, std::string::npos);
  EXPECT_EQ(html.find("NaN", figures), std::string::npos);
  EXPECT_EQ(html.find("Infinity", figures), std::string::npos);
  // The generic plots of every CSV are not added next to the dedicated ones.
  EXPECT_EQ(html.find("\"samples_preview.csv\""), std::string::npos);
}

TEST(ToolpathReport, LargeOutputsAreThinnedAndLongProgramsKeepTheirLineNumbers) {
  // 8 × 4000 = 32 000 preview rows of a program whose lines start at 1 234 567;
  // a 0.1 mm stock grid of 401 × 401 nodes.
  const rd::Content c = content_of(pocket_files(4000, 0.1, 1234567));
  const rd::Figure* path = figure_titled(c, "Tool path");
  ASSERT_NE(path, nullptr);
  for (const json& t : path->data)
    EXPECT_LE(t["x"].size(), 20100u);
  EXPECT_EQ(path->data[0]["customdata"][0][0], 1234569);  // not 1.23457e6
  const rd::Figure* time = figure_titled(c, "Engagement and loads over time");
  ASSERT_NE(time, nullptr);
  for (const json& t : time->data)
    EXPECT_LE(t["x"].size(), 5000u);
  // The thinned force keeps its largest value (the extremes of every run).
  double top = 0.0;
  for (const json& t : time->data)
    if (t["name"] == "peak force")
      for (const json& v : t["y"])
        top = std::max(top, v.is_number() ? v.get<double>() : 0.0);
  EXPECT_NEAR(top, 800.0, 1.0);
  const rd::Figure* map = figure_titled(c, "Final stock, height map");
  ASSERT_NE(map, nullptr);
  EXPECT_LE(map->data[0]["x"].size(), 201u);
  EXPECT_LE(map->data[0]["y"].size(), 201u);
  EXPECT_DOUBLE_EQ(map->data[0]["x"].back().get<double>(), 40.0);  // the far edge is kept
}

TEST(ToolpathReport, MissingFilesLeaveTheirFiguresOutWithANote) {
  rr::Files files = pocket_files();
  files.erase("stock.csv");
  files.erase("moves.csv");
  const rd::Content c = content_of(files);
  EXPECT_NE(figure_titled(c, "Tool path"), nullptr);
  EXPECT_EQ(figure_titled(c, "Final stock, height map"), nullptr);
  EXPECT_EQ(c.notes.size(), 2u);
  const std::string html = rr::render_html(files);
  EXPECT_NE(html.find("stock.csv is not in the output folder"), std::string::npos);
}
