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

namespace test_toolpath_report_cpp {

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

// ------------------------------------------------------------ the robot along the path

namespace {

/// The pocket's samples with the robot columns of a 6-axis robot appended:
/// line 4 (the full-width slot) chatters, its margin smallest (0.62) and its
/// form error largest (42 µm) mid-move; line 7 cuts 3 µm too deep; the cells
/// of samples not in the cut are empty, the first sample is out of reach.
std::string robot_samples(int per_move) {
  const std::string pocket = pocket_samples(per_move);
  std::string csv =
      pocket.substr(0, pocket.find('\n')) +
      ",psi_deg,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg,reachable,joint_margin_deg,"
      "singularity,ap_limit_mm,margin,chatter,chatter_freq_hz,dev_x_um,dev_y_um,dev_z_um,"
      "deflection_um,form_error_um,floor_error_um,dynamics_recomputed\n";
  std::size_t start = pocket.find('\n') + 1;
  for (int i = 0; start < pocket.size(); ++i) {
    const std::size_t end = pocket.find('\n', start);
    csv += pocket.substr(start, end - start);
    start = end + 1;
    const int move = i / per_move;  // 0-based: lines 4-7 are moves 3-6
    const double u = static_cast<double>(i % per_move + 1) / per_move;
    const double q1 = -20.0 + 40.0 * u + move;
    const std::string joints =
        i == 0 ? ",,,,,,,0,,"
               : fmt::format(",{},-90,{},0,{},{},1,{},{}", q1, 80.0 - move, 45.0 + u, q1 + 10.0,
                             12.0 + move, 0.3 + 0.01 * move);
    csv += (i == 0 ? ",0" : ",15") + joints;
    if (move < 3 || move > 6) {
      csv += ",,,0,,0,0,0,0,,,0\n";
      continue;
    }
    const bool slot = move == 3;
    const double ap_limit = slot ? 3.1 + 2.0 * std::abs(u - 0.5) : 8.0 + u;
    const double margin = ap_limit / 5.0;
    const double form = slot        ? 12.0 + 30.0 * std::sin(std::numbers::pi * u)
                        : move == 6 ? -3.0
                                    : 5.0;
    const double deflection = std::abs(form) * 1.4;
    csv += fmt::format(",{},{},{},{},{},{},{},{},{},{},{}\n", ap_limit, margin, margin < 1 ? 1 : 0,
                       slot ? 620.0 : 0.0, 0.6 * deflection, 0.8 * deflection, 0.0, deflection,
                       form, 0.2 * form, i % 10 == 0 ? 1 : 0);
  }
  return csv;
}

json robot_along_path() {
  return {{"robot", "KR 270 R2900-class"},
          {"dof", 6},
          {"samples", 400},
          {"analysed_samples", 399},
          {"unreachable_samples", 1},
          {"joint_limit_samples", 0},
          {"fraction_at_risk", 0.12},
          {"chatter_samples", 50},
          {"min_margin", 0.62},
          {"min_margin_line", 4},
          {"max_form_error_um", 42.0},
          {"max_form_error_line", 4},
          {"max_deflection_um", 58.8},
          {"dynamics_recomputations", 120},
          {"shortcut_max_error", 0.004},
          {"worst_lines",
           json::array({{{"line", 4},
                         {"t_s", 1.73},
                         {"margin", 0.62},
                         {"ap_mm", 5.0},
                         {"ap_limit_mm", 3.1},
                         {"spindle_rpm", 8000},
                         {"chatter_freq_hz", 620.0},
                         {"form_error_um", 42.0},
                         {"advice", "chatter: lower ap to 2.8 mm or move the spindle to 9100 rpm"}},
                        {{"line", 5}, {"margin", 1.6}, {"advice", "stable"}}})},
          {"worst_posture",
           {{"line", 4},
            {"q_deg", {10, -90, 80, 45.5, 0, 20}},
            {"joint_origins_mm",
             {{0, 0, 0},
              {350, 0, 675},
              {350, 0, 1825},
              {1500, 0, 1866},
              {1700, 0, 1866},
              {1800, 0, 1866},
              {1800, 0, 600}}},
            {"tool_tip_mm", {1800, 0, 600}},
            {"tool_axis", {0, 0, 1}}}}};
}

rr::Files robot_files(int per_move = 50) {
  rr::Files files = pocket_files(per_move);
  json summary = pocket_summary();
  summary["robot_along_path"] = robot_along_path();
  files["summary.json"] = summary.dump(2);
  files["samples_preview.csv"] = robot_samples(per_move);
  return files;
}

std::vector<std::string> trace_names(const rd::Figure& f) {
  std::vector<std::string> names;
  for (const json& t : f.data)
    names.push_back(t.value("name", std::string()));
  return names;
}

bool has_null(const json& array) {
  return std::any_of(array.begin(), array.end(), [](const json& v) { return v.is_null(); });
}

}  // namespace

TEST(ToolpathRobotReport, PathColourMenuAddsChatterMarginAndFormError) {
  const rd::Content c = content_of(robot_files());
  EXPECT_TRUE(c.notes.empty());
  const rd::Figure* path = figure_titled(c, "Tool path");
  ASSERT_NE(path, nullptr);
  const json& feed = path->data[0];
  const json& buttons = path->layout["updatemenus"][0]["buttons"];
  ASSERT_EQ(buttons.size(), 4u);
  EXPECT_EQ(buttons[2]["label"], "colour: chatter margin");
  EXPECT_EQ(buttons[3]["label"], "colour: form error");
  // Margin: diverging about 1, red at the bottom, every feed point coloured.
  const json& margin = buttons[2]["args"][0];
  EXPECT_EQ(margin["marker.colorbar.title.text"], "chatter margin (ap limit / ap)");
  const double low = margin["marker.cmin"].get<double>(),
               high = margin["marker.cmax"].get<double>();
  EXPECT_LT(low, 0.62);
  EXPECT_NEAR(low + high, 2.0, 1e-9);
  EXPECT_EQ(margin["marker.colorscale"][0][0][1], "#b2182b");
  EXPECT_EQ(margin["line.color"][0].size(), feed["x"].size());
  EXPECT_FALSE(has_null(margin["marker.color"][0]));
  // Form error: sequential from its most negative (-3 µm) to its largest (42 µm).
  const json& form = buttons[3]["args"][0];
  EXPECT_EQ(form["marker.colorscale"][0], "Cividis");
  EXPECT_NEAR(form["marker.cmin"].get<double>(), -3.0, 1e-9);
  EXPECT_NEAR(form["marker.cmax"].get<double>(), 42.0, 0.01);
  EXPECT_EQ(form["marker.colorbar.title.text"], "form error (µm)");
  // The engagement and force buttons now restore their own scale.
  EXPECT_EQ(buttons[0]["args"][0]["marker.colorscale"][0], "Viridis");
  EXPECT_EQ(buttons[1]["args"][0]["line.cmin"], 0);
  // Hover: the program line, margin, ap and its limit, form error.
  const std::string hover = feed["hovertemplate"];
  for (const char* part :
       {"line %{customdata[0]}", "ap %{customdata[2]", "chatter margin %{customdata[5]}",
        "stable ap %{customdata[6]} mm", "form error %{customdata[7]} µm"})
    EXPECT_NE(hover.find(part), std::string::npos) << part;
  EXPECT_EQ(feed["customdata"][0][0], 3);
  EXPECT_EQ(feed["customdata"][0][5], "—");  // the plunge into air: no margin
  bool slot_seen = false;
  for (const json& row : feed["customdata"])
    if (!row.empty() && row[0] == 4 && !slot_seen) {
      slot_seen = true;
      EXPECT_NE(row[5], "—");
      EXPECT_NE(row[6], "—");
    }
  EXPECT_TRUE(slot_seen);
  EXPECT_NE(path->caption.find("chatter margin"), std::string::npos);
}

TEST(ToolpathRobotReport, MarginDeflectionAndJointsOverTime) {
  const rd::Content c = content_of(robot_files());
  const rd::Figure* f = figure_titled(c, "Chatter margin, deflection and joints over time");
  ASSERT_NE(f, nullptr);
  const std::vector<std::string> names = trace_names(*f);
  for (const char* name :
       {"chatter margin", "deflection", "form error", "floor error", "q1", "q6", "smallest margin"})
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  for (const json& t : f->data)
    EXPECT_NE(t["hovertemplate"].get<std::string>().find("line"), std::string::npos);
  EXPECT_EQ(f->layout["yaxis"]["title"]["text"], "chatter margin (ap limit / ap)");
  EXPECT_EQ(f->layout["yaxis2"]["title"]["text"], "deflection, error (µm)");
  EXPECT_EQ(f->layout["yaxis3"]["title"]["text"], "joint angle (°)");
  EXPECT_EQ(f->layout["xaxis3"]["title"]["text"], "time (s)");
  for (const json& t : f->data) {
    if (t["name"] == "q1") {
      EXPECT_EQ(t["yaxis"], "y3");
    } else if (t["name"] == "form error") {
      EXPECT_EQ(t["yaxis"], "y2");
    } else if (t["name"] == "chatter margin") {
      EXPECT_TRUE(has_null(t["y"]));  // not in the cut: gaps
    }
  }
  // The line at a margin of 1 and the smallest margin (0.62, line 4) marked.
  EXPECT_EQ(f->layout["shapes"][0]["y0"], 1);
  EXPECT_EQ(f->layout["shapes"][0]["yref"], "y");
  const json& star = f->data.back();
  EXPECT_EQ(star["name"], "smallest margin");
  EXPECT_NEAR(star["y"][0].get<double>(), 0.62, 1e-9);
  EXPECT_NE(star["hovertemplate"].get<std::string>().find("line 4"), std::string::npos);
}

TEST(ToolpathRobotReport, FormErrorMapOnThePart) {
  const rd::Content c = content_of(robot_files());
  const rd::Figure* f = figure_titled(c, "Form error on the part, top view");
  ASSERT_NE(f, nullptr);
  const json& points = f->data[0];
  EXPECT_EQ(points["mode"], "markers");
  EXPECT_EQ(points["x"].size(), 200u);  // the 4 cutting moves' samples only
  EXPECT_EQ(points["marker"]["colorbar"]["title"]["text"], "form error (µm)");
  EXPECT_NEAR(points["marker"]["cmin"].get<double>(), -3.0, 1e-9);
  EXPECT_NEAR(points["marker"]["cmax"].get<double>(), 42.0, 0.01);
  EXPECT_NE(points["hovertemplate"].get<std::string>().find("line %{customdata[0]}"),
            std::string::npos);
  const json& star = f->data[1];
  EXPECT_EQ(star["name"], "largest form error");
  EXPECT_NE(star["hovertemplate"].get<std::string>().find("42 µm<br>line 4"), std::string::npos);
  EXPECT_EQ(f->layout["shapes"][0]["type"], "rect");
  EXPECT_EQ(f->layout["shapes"][0]["x1"], 40);
  EXPECT_EQ(f->layout["yaxis"]["scaleanchor"], "x");
  EXPECT_EQ(f->layout["xaxis"]["title"]["text"], "x (mm)");
}

TEST(ToolpathRobotReport, RobotDrawnAtTheWorstPosture) {
  const rd::Content c = content_of(robot_files());
  const rd::Figure* f = figure_titled(c, "Robot at the worst posture, line 4");
  ASSERT_NE(f, nullptr);
  const json& arm = f->data[0];
  EXPECT_EQ(arm["type"], "scatter3d");
  EXPECT_EQ(arm["mode"], "lines+markers");
  ASSERT_EQ(arm["x"].size(), 7u);
  EXPECT_EQ(arm["z"][1], 675);
  EXPECT_EQ(arm["text"][1], "joint 2, q2 = -90°");
  EXPECT_EQ(arm["text"][6], "tool tip");
  const std::vector<std::string> names = trace_names(*f);
  for (const char* name : {"base", "tool tip", "tool axis"})
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  const json& axis = f->data.back();
  EXPECT_EQ(axis["name"], "tool axis");
  EXPECT_EQ(axis["z"][0], 600);
  EXPECT_GT(axis["z"][1].get<double>(), 600.0);  // along +z from the tip
  EXPECT_EQ(axis["x"][1], 1800);
  // True to scale: a cube of equal ranges around the arm (flat in y here).
  const json& scene = f->layout["scene"];
  EXPECT_EQ(scene["aspectmode"], "cube");
  EXPECT_EQ(scene["zaxis"]["title"]["text"], "z (mm)");
  auto span = [&](const char* a) {
    return scene[a]["range"][1].get<double>() - scene[a]["range"][0].get<double>();
  };
  EXPECT_NEAR(span("xaxis"), span("yaxis"), 1e-6);
  EXPECT_NEAR(span("zaxis"), span("yaxis"), 1e-6);
  EXPECT_GE(span("zaxis"), 1866.0);
  EXPECT_LT(scene["yaxis"]["range"][0].get<double>(), 0.0);
  EXPECT_NE(f->caption.find("KR 270 R2900-class"), std::string::npos);
}

TEST(ToolpathRobotReport, HeadlineAndWorstLinesWithTheAdvice) {
  const rd::Content c = content_of(robot_files());
  const rd::TextTable* head = table_starting(c, "The robot along the path");
  ASSERT_NE(head, nullptr);
  auto row = [&](const std::string& name) {
    for (const auto& r : head->rows)
      if (r[0] == name)
        return r;
    return std::vector<std::string>{};
  };
  EXPECT_EQ(row("robot"), (std::vector<std::string>{"robot", "KR 270 R2900-class, 6 axes", ""}));
  EXPECT_EQ(row("fraction at risk of chatter")[1], "12 %");
  EXPECT_EQ(row("smallest chatter margin"),
            (std::vector<std::string>{"smallest chatter margin", "0.62", "4"}));
  EXPECT_EQ(row("largest form error"),
            (std::vector<std::string>{"largest form error", "42 µm", "4"}));
  EXPECT_EQ(row("dynamics recomputations")[1], "120");
  EXPECT_EQ(row("shortcut's measured error")[1], "0.004");
  EXPECT_EQ(row("samples analysed")[1], "399 of 400");
  const rd::TextTable* worst = table_starting(c, "Program lines with the smallest chatter margin");
  ASSERT_NE(worst, nullptr);
  ASSERT_EQ(worst->rows.size(), 2u);
  EXPECT_EQ(worst->header.back(), "advice");
  EXPECT_EQ(worst->rows[0], (std::vector<std::string>{
                                "4", "1.73", "0.62", "5", "3.1", "8000", "620", "42",
                                "chatter: lower ap to 2.8 mm or move the spindle to 9100 rpm"}));
  // Keys an item lacks read "—".
  EXPECT_EQ(worst->rows[1][0], "5");
  EXPECT_EQ(worst->rows[1][3], "—");
  EXPECT_EQ(worst->rows[1].back(), "stable");
}

TEST(ToolpathRobotReport, PageHoldsTheRobotPartsAndNoNaN) {
  const std::string html = rr::render_html(robot_files());
  for (const char* part :
       {"Tool path", "colour: chatter margin", "colour: form error",
        "Chatter margin, deflection and joints over time", "Form error on the part, top view",
        "Robot at the worst posture, line 4", "The robot along the path",
        "chatter: lower ap to 2.8 mm or move the spindle to 9100 rpm",
        "Engagement and loads over time", "Final stock, height map"})
    EXPECT_NE(html.find(part), std::string::npos) << part;
  const std::size_t figures = html.find("id=\"robomill-figures\"");
  ASSERT_NE(figures, std::string::npos);
  EXPECT_EQ(html.find("NaN", figures), std::string::npos);
  EXPECT_EQ(html.find("Infinity", figures), std::string::npos);
}

TEST(ToolpathRobotReport, AFolderWithoutTheRobotRendersWithoutIt) {
  const rd::Content c = content_of(pocket_files());
  for (const char* title :
       {"Chatter margin, deflection and joints over time", "Form error on the part, top view"})
    EXPECT_EQ(figure_titled(c, title), nullptr) << title;
  for (const rd::Figure& f : c.figures)
    EXPECT_FALSE(f.title.starts_with("Robot at the worst posture"));
  EXPECT_EQ(table_starting(c, "The robot along the path"), nullptr);
  EXPECT_EQ(table_starting(c, "Program lines with the smallest chatter margin"), nullptr);
  const rd::Figure* path = figure_titled(c, "Tool path");
  ASSERT_NE(path, nullptr);
  EXPECT_EQ(path->layout["updatemenus"][0]["buttons"].size(), 2u);
  EXPECT_FALSE(
      path->layout["updatemenus"][0]["buttons"][0]["args"][0].contains("marker.colorscale"));
  EXPECT_EQ(path->data[0]["hovertemplate"].get<std::string>().find("margin"), std::string::npos);
  EXPECT_EQ(path->data[0]["customdata"][0].size(), 5u);
  EXPECT_EQ(c.figures.size(), 4u);
  const std::string html = rr::render_html(pocket_files());
  EXPECT_EQ(html.find("chatter margin"), std::string::npos);
}

TEST(ToolpathRobotReport, PartialOrMalformedRobotOutputsAreSkippedQuietly) {
  // The summary's robot without its columns: the posture and the tables only.
  rr::Files files = pocket_files();
  json summary = pocket_summary();
  summary["robot_along_path"] = robot_along_path();
  files["summary.json"] = summary.dump();
  rd::Content c = content_of(files);
  EXPECT_EQ(figure_titled(c, "Chatter margin, deflection and joints over time"), nullptr);
  EXPECT_NE(figure_titled(c, "Robot at the worst posture, line 4"), nullptr);
  EXPECT_NE(table_starting(c, "The robot along the path"), nullptr);
  // Keys missing or of the wrong kind: what remains is shown, nothing fails.
  summary["robot_along_path"] = {
      {"min_margin", "low"},
      {"fraction_at_risk", 0.5},
      {"worst_lines", json::array({1, "x"})},
      {"worst_posture", {{"joint_origins_mm", {{0, 0}, "a", {1, 2, 3}}}}}};
  files["summary.json"] = summary.dump();
  files["samples_preview.csv"] = robot_samples(50);
  c = content_of(files);
  EXPECT_TRUE(c.notes.empty());
  for (const rd::Figure& f : c.figures)
    EXPECT_FALSE(f.title.starts_with("Robot at the worst posture"));  // one point only
  const rd::TextTable* head = table_starting(c, "The robot along the path");
  ASSERT_NE(head, nullptr);
  ASSERT_EQ(head->rows.size(), 1u);
  EXPECT_EQ(head->rows[0][1], "50 %");
  const rd::TextTable* worst = table_starting(c, "Program lines with the smallest chatter margin");
  ASSERT_NE(worst, nullptr);
  EXPECT_EQ(worst->rows[0].back(), "none");
  EXPECT_NE(figure_titled(c, "Form error on the part, top view"), nullptr);
  // The summary without the robot, the preview with: the figures from the preview.
  files["summary.json"] = pocket_summary().dump();
  c = content_of(files);
  EXPECT_NE(figure_titled(c, "Chatter margin, deflection and joints over time"), nullptr);
  EXPECT_EQ(table_starting(c, "The robot along the path"), nullptr);
  // A preview whose margin column is empty throughout: no timeline, no crash.
  std::string blank =
      "line,t_s,x_mm,y_mm,z_mm,motion,margin,form_error_um\n"
      "1,0.1,0,0,0,linear,,\n2,0.2,1,0,0,linear,,\n";
  files["samples_preview.csv"] = blank;
  c = content_of(files);
  EXPECT_EQ(figure_titled(c, "Chatter margin, deflection and joints over time"), nullptr);
  EXPECT_EQ(figure_titled(c, "Form error on the part, top view"), nullptr);
  const std::string html = rr::render_html(files);
  EXPECT_EQ(html.find("NaN", html.find("id=\"robomill-figures\"")), std::string::npos);
}

TEST(ToolpathRobotReport, LongPreviewsAreThinnedKeepingTheSmallestMargin) {
  const rd::Content c = content_of(robot_files(4000));  // 32 000 rows
  const rd::Figure* f = figure_titled(c, "Chatter margin, deflection and joints over time");
  ASSERT_NE(f, nullptr);
  double lowest = 10.0;
  for (const json& t : f->data) {
    EXPECT_LE(t["x"].size(), 5000u);
    if (t["name"] == "chatter margin")
      for (const json& v : t["y"])
        lowest = std::min(lowest, v.is_number() ? v.get<double>() : 10.0);
  }
  EXPECT_NEAR(lowest, 0.62, 1e-9);
  const rd::Figure* map = figure_titled(c, "Form error on the part, top view");
  ASSERT_NE(map, nullptr);
  EXPECT_LE(map->data[0]["x"].size(), 20001u);
  const rd::Figure* path = figure_titled(c, "Tool path");
  ASSERT_NE(path, nullptr);
  EXPECT_EQ(path->layout["updatemenus"][0]["buttons"][2]["args"][0]["marker.color"][0].size(),
            path->data[0]["x"].size());
}

TEST(ToolpathRobotReport, OptimizedProgramShowsTheFeedsAndTheBeforeAfterTable) {
  // summary.json's optimization as `toolpath --optimize` writes it: a speed
  // change, two lines slowed (force, deflection), one sped up to feed_max.
  rr::Files files = robot_files();
  json summary = json::parse(files.at("summary.json"));
  auto change = [](int line, double from, double to, const char* binding, double force_before,
                   double force_after) {
    return json{{"line", line},
                {"programmed_mm_min", from},
                {"chosen_mm_min", to},
                {"binding", binding},
                {"before", {{"force_peak_N", force_before}, {"deflection_um", 60.0}}},
                {"after", {{"force_peak_N", force_after}, {"deflection_um", 49.0}}}};
  };
  summary["optimization"] = {
      {"changed", true},
      {"program", "program_optimized.nc"},
      {"spindle_choices",
       json::array({{{"lines", {3, 8}}, {"programmed_rpm", 8000.0}, {"chosen_rpm", 12000.0}}})},
      {"redundancy", nullptr},
      {"feeds",
       {{"runs", 4},
        {"lines_with_feed", 5},
        {"lines_changed", 3},
        {"changes", json::array({change(4, 600, 344, "force", 134, 117),
                                 change(5, 600, 207, "deflection", 120, 108),
                                 change(6, 500, 2000, "feed_max", 40, 54)})}}},
      {"after",
       {{"min_margin", 1.58},
        {"chatter_samples", 0},
        {"max_force_N", 119.5},
        {"max_deflection_um", 49.8},
        {"cycle_time_s", 62.3}}},
      {"cycle_time_before_s", 41.0},
      {"samples_newly_at_risk", 0}};
  files["summary.json"] = summary.dump(2);
  const rd::Content c = content_of(files);
  const rd::Figure* f = figure_titled(c, "The better program: feed per program line");
  ASSERT_NE(f, nullptr);
  const std::vector<std::string> names = trace_names(*f);
  EXPECT_EQ(names,
            (std::vector<std::string>{"programmed feed", "chosen, set by force",
                                      "chosen, set by deflection", "chosen, set by feed_max"}));
  EXPECT_EQ(f->data[0]["y"].size(), 3u);
  EXPECT_NE(f->data[1]["text"][0].get<std::string>().find("peak force 134 → 117 N"),
            std::string::npos);
  const rd::TextTable* t = table_starting(c, "The better program");
  ASSERT_NE(t, nullptr);
  auto row = [&](const std::string& label) -> std::vector<std::string> {
    for (const auto& r : t->rows)
      if (r.front() == label)
        return r;
    return {};
  };
  EXPECT_EQ(row("spindle, lines 3-8"),
            (std::vector<std::string>{"spindle, lines 3-8", "8000 rpm", "12000 rpm"}));
  EXPECT_EQ(row("cycle time"), (std::vector<std::string>{"cycle time", "41 s", "62.3 s"}));
  EXPECT_EQ(row("largest peak force").at(2), "119.5 N");
  const std::string html = rr::render_html(files);
  EXPECT_EQ(html.find("NaN", html.find("id=\"robomill-figures\"")), std::string::npos);
  // Without a change (or without --optimize) neither appears.
  summary["optimization"]["changed"] = false;
  files["summary.json"] = summary.dump(2);
  const rd::Content kept = content_of(files);
  EXPECT_EQ(figure_titled(kept, "The better program: feed per program line"), nullptr);
  EXPECT_EQ(table_starting(kept, "The better program"), nullptr);
}

}  // namespace test_toolpath_report_cpp
