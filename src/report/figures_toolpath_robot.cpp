// The report of `robomill toolpath` with a robot along the path: the chatter
// margin and the form error on the 3-D path's colour menu, the margin, the
// deflection and the joint angles over time, the form error as a map on the
// part, the robot drawn at its worst posture, the headline numbers and the
// worst program lines with their advice, and with --optimize the feeds
// written back and the before/after table. From the robot columns of
// samples_preview.csv and summary.json's "robot_along_path"; a folder
// without them gets none of these (and a page as before).

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "detail.hpp"
#include "figure_helpers.hpp"

namespace robomill::report::detail {
namespace {

using nlohmann::json;

constexpr std::size_t kMapPoints = 20000;  // markers of the form-error map
constexpr double kMarginAxisTop = 5.0;     // the margin axis stops here (stable far beyond)
constexpr const char* kJointColors[] = {"#1b9e77", "#d95f02", "#7570b3", "#e7298a",
                                        "#66a61e", "#e6ab02", "#a6761d", "#666666"};
constexpr const char* kRiskColor = "#d62728";
constexpr const char* kRobotColor = "#3d4b5c";
constexpr const char* kFormScale = "Cividis";  // sequential, apart from the engagement's Viridis

/// Diverging about a margin of 1 (the scale's middle): red below, blue above.
json margin_scale() {
  return json::array({json::array({0.0, "#b2182b"}), json::array({0.35, "#ef8a62"}),
                      json::array({0.5, "#e3c565"}), json::array({0.65, "#67a9cf"}),
                      json::array({1.0, "#2166ac"})});
}

double at_or_nan(const std::vector<double>& v, std::size_t i) {
  return i < v.size() ? v[i] : std::nan("");
}

/// The smallest and largest finite value of `v`; {NaN, NaN} if none.
std::pair<double, double> finite_range(const std::vector<double>& v) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double x : v)
    if (std::isfinite(x))
      lo = std::min(lo, x), hi = std::max(hi, x);
  return lo <= hi ? std::pair{lo, hi} : std::pair{std::nan(""), std::nan("")};
}

/// The colour range of the form error: from 0 (or below, where the tool cut
/// too deep) to the largest.
std::pair<double, double> form_range(const std::vector<double>& v) {
  auto [lo, hi] = finite_range(v);
  lo = std::isfinite(lo) ? std::min(0.0, lo) : 0.0;
  hi = std::isfinite(hi) && hi > lo ? hi : lo + 1.0;
  return {lo, hi};
}

/// The margin's colour range, symmetric about 1 (the scale's middle), from
/// 1 ± 0.25 to 0 .. 2.
std::pair<double, double> margin_range(const std::vector<double>& v) {
  const auto [lo, hi] = finite_range(v);
  const double half = std::isfinite(lo) ? std::clamp(std::max(1.0 - lo, hi - 1.0), 0.25, 1.0) : 1.0;
  return {1.0 - half, 1.0 + half};
}

/// The joint-angle columns q1_deg, q2_deg ... in joint order.
std::vector<std::string> joint_columns(const Table& s) {
  std::vector<std::pair<int, std::string>> found;
  for (const std::string& name : s.columns()) {
    if (name.size() < 6 || name.front() != 'q' || !name.ends_with("_deg"))
      continue;
    const std::string digits = name.substr(1, name.size() - 5);
    if (digits.empty() ||
        !std::all_of(digits.begin(), digits.end(), [](char ch) { return ch >= '0' && ch <= '9'; }))
      continue;
    found.emplace_back(std::atoi(digits.c_str()), name);
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> out;
  for (auto& [index, name] : found)
    out.push_back(std::move(name));
  return out;
}

// ------------------------------------------------------------ over time

/// Margin on top (a line at 1), deflection and form error below, the joint
/// angles at the bottom, over one time axis.
void robot_time_figure(const Table& s, Content& c) {
  if (!s.has("t_s"))
    return;
  const std::vector<double> t = s.numbers("t_s"), line = s.numbers("line");
  struct Series {
    std::string column, name, unit;
  };
  std::vector<std::vector<Series>> rows;
  std::vector<std::string> titles;
  rows.push_back({{"margin", "chatter margin", ""}});
  titles.push_back("chatter margin (ap limit / ap)");
  std::vector<Series> deflection;
  for (const auto& [column, name] :
       {std::pair{"deflection_um", "deflection"}, std::pair{"form_error_um", "form error"},
        std::pair{"floor_error_um", "floor error"}})
    if (s.has(column))
      deflection.push_back({column, name, "µm"});
  // 004's steady-state offset, where the job asked for it (robot_path.offset).
  if (s.has("offset_um") && std::isfinite(finite_range(s.numbers("offset_um")).second))
    deflection.push_back({"offset_um", "004 offset", "µm"});
  if (!deflection.empty()) {
    rows.push_back(std::move(deflection));
    titles.push_back("deflection, error (µm)");
  }
  std::vector<Series> joints;
  for (const std::string& column : joint_columns(s))
    joints.push_back({column, column.substr(0, column.size() - 4), "°"});
  if (!joints.empty()) {
    rows.push_back(std::move(joints));
    titles.push_back(axis_title("joint_angle_deg"));
  }

  Figure f;
  f.title = "Chatter margin, deflection and joints over time";
  const std::vector<double> margin = s.numbers("margin");
  const auto [margin_low, margin_high] = finite_range(margin);
  if (!std::isfinite(margin_high))
    return;  // no sample in the cut
  const bool cut_axis = margin_high > kMarginAxisTop;
  if (cut_axis)
    f.layout["yaxis"] = {{"range", {0, kMarginAxisTop}}};
  const std::vector<double> weights = {1.3, 1.0, 1.0};
  stack(f, axis_title("t_s"), titles,
        std::vector<double>(weights.begin(),
                            weights.begin() + static_cast<std::ptrdiff_t>(rows.size())));
  f.height_px = 300 + 220 * static_cast<int>(rows.size());
  f.layout["hovermode"] = "x unified";
  f.layout["legend"] = {{"orientation", "h"}, {"y", -0.1}};
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (std::size_t j = 0; j < rows[r].size(); ++j) {
      const Series& item = rows[r][j];
      const std::vector<double> v = s.numbers(item.column);
      const std::vector<std::size_t> at = envelope(v, kTimePoints);
      json tr = trace(pick(t, at), pick(v, at), item.name);
      tr["customdata"] = integers(pick(line, at));
      tr["hovertemplate"] = fmt::format("{} %{{y:.4g}}{} (line %{{customdata}})<extra></extra>",
                                        item.name, item.unit.empty() ? "" : " " + item.unit);
      // The margin blue, the deflections after it, the joints a palette of their own.
      const bool joint = item.unit == "°";
      tr["line"] = {{"color", joint ? kJointColors[j % 8] : kColors[(r + j) % 8]}, {"width", 1.2}};
      f.data.push_back(on_row(tr, static_cast<int>(r)));
    }
  // Stable above the line at 1; the smallest margin as a star.
  f.layout["shapes"] =
      json::array({{{"type", "line"},
                    {"xref", "paper"},
                    {"yref", "y"},
                    {"x0", 0},
                    {"x1", 1},
                    {"y0", 1},
                    {"y1", 1},
                    {"line", {{"color", kRiskColor}, {"dash", "dash"}, {"width", 1}}}}});
  std::size_t lowest = margin.size();
  for (std::size_t i = 0; i < margin.size(); ++i)
    if (std::isfinite(margin[i]) && (lowest == margin.size() || margin[i] < margin[lowest]))
      lowest = i;
  if (lowest < margin.size() && std::isfinite(at_or_nan(t, lowest))) {
    json star = trace({t[lowest]}, {margin[lowest]}, "smallest margin", "markers");
    star["marker"] = {{"color", kRiskColor}, {"symbol", "star"}, {"size", 14}};
    star["hovertemplate"] = fmt::format("smallest margin %{{y:.3g}} (line {})<extra></extra>",
                                        integer_text(at_or_nan(line, lowest)));
    f.data.push_back(star);
  }
  f.caption = fmt::format(
      "Per sample of samples_preview.csv over the program's time: the chatter margin (the stable "
      "axial depth at the sample's spindle speed and engagement over the depth cut; chatter "
      "below the dashed line at 1{}), the static tool-tip deflection and its share on the "
      "machined wall (form error) and floor (positive where material is left), and the robot's "
      "joint angles. Gaps: samples not in the cut or out of reach. The star marks the smallest "
      "margin shown ({} at line {}); hover shows each sample's program line. Long series keep "
      "the smallest and largest value of each run of samples.",
      cut_axis ? fmt::format("; axis cut at {}", kMarginAxisTop) : "", display(margin_low),
      integer_text(at_or_nan(line, lowest)));
  c.figures.push_back(std::move(f));
}

// ------------------------------------------------------------ the form error on the part

void form_error_map(const Table& s, const json& summary, Content& c) {
  if (!s.has("form_error_um") || !s.has("x_mm") || !s.has("y_mm"))
    return;
  const std::vector<double> x = s.numbers("x_mm"), y = s.numbers("y_mm"),
                            form = s.numbers("form_error_um"), line = s.numbers("line"),
                            engagement = s.numbers("engagement_deg"),
                            deflection = s.numbers("deflection_um"), margin = s.numbers("margin");
  const bool has_engagement = s.has("engagement_deg");
  std::vector<std::size_t> engaged;
  for (std::size_t i = 0; i < form.size(); ++i)
    if (std::isfinite(form[i]) && std::isfinite(at_or_nan(x, i)) &&
        std::isfinite(at_or_nan(y, i)) && (!has_engagement || at_or_nan(engagement, i) > 0.0))
      engaged.push_back(i);
  if (engaged.empty())
    return;
  // The largest error (either sign) is always shown.
  std::size_t worst = engaged.front();
  for (std::size_t i : engaged)
    if (std::abs(form[i]) > std::abs(form[worst]))
      worst = i;
  std::vector<std::size_t> shown;
  for (std::size_t k : thin(engaged.size(), kMapPoints))
    shown.push_back(engaged[k]);
  if (std::find(shown.begin(), shown.end(), worst) == shown.end())
    shown.push_back(worst);
  // The largest errors drawn last, on top.
  std::stable_sort(shown.begin(), shown.end(),
                   [&](std::size_t a, std::size_t b) { return form[a] < form[b]; });

  std::vector<double> px, py, pf;
  json custom = json::array();
  for (std::size_t i : shown) {
    px.push_back(x[i]), py.push_back(y[i]), pf.push_back(form[i]);
    custom.push_back(
        json::array({integer(at_or_nan(line, i)), display(form[i]),
                     display(at_or_nan(deflection, i)), display(at_or_nan(margin, i))}));
  }
  const auto [lo, hi] = form_range(pf);
  const std::string title = axis_title("form_error_um");
  Figure f = xy_figure("Form error on the part, top view", axis_title("x_mm"), axis_title("y_mm"));
  json points = trace(px, py, "form error", "markers");
  points["customdata"] = custom;
  points["showlegend"] = false;
  points["marker"] = {{"color", values(pf)},
                      {"colorscale", kFormScale},
                      {"cmin", rounded(lo)},
                      {"cmax", rounded(hi)},
                      {"size", 5},
                      {"showscale", true},
                      {"colorbar", {{"title", {{"text", title}, {"side", "right"}}}}}};
  points["hovertemplate"] =
      "line %{customdata[0]}<br>form error %{customdata[1]} µm<br>deflection %{customdata[2]} "
      "µm, chatter margin %{customdata[3]}<br>x %{x} y %{y} mm<extra></extra>";
  f.data.push_back(points);
  json star = trace({x[worst]}, {y[worst]}, "largest form error", "markers");
  star["marker"] = {{"color", kRiskColor},
                    {"symbol", "star"},
                    {"size", 14},
                    {"line", {{"color", "#fff"}, {"width", 1}}}};
  star["hovertemplate"] = fmt::format("largest form error {} µm<br>line {}<extra></extra>",
                                      display(form[worst]), integer_text(at_or_nan(line, worst)));
  f.data.push_back(star);
  // The stock's outline (summary.json), for the part's extent.
  const json stock = summary.value("stock", json::object());
  if (stock.is_object()) {
    const json low = stock.value("min_mm", json()), high = stock.value("max_mm", json());
    if (low.is_array() && high.is_array() && low.size() >= 2 && high.size() >= 2 &&
        low[0].is_number() && low[1].is_number() && high[0].is_number() && high[1].is_number())
      f.layout["shapes"] = json::array({{{"type", "rect"},
                                         {"x0", low[0]},
                                         {"y0", low[1]},
                                         {"x1", high[0]},
                                         {"y1", high[1]},
                                         {"layer", "below"},
                                         {"line", {{"color", "#9aa3ad"}, {"dash", "dot"}}}}});
  }
  f.layout["yaxis"]["scaleanchor"] = "x";
  f.layout["yaxis"]["scaleratio"] = 1;
  f.layout["xaxis"]["constrain"] = "domain";
  f.height_px = 560;
  f.caption = fmt::format(
      "The static form error of every sample in the cut (samples_preview.csv, {} of {} shown) at "
      "its x and y, seen from above: the tool-tip deflection on the machined wall's normal, "
      "positive where material is left, negative where the tool cut too deep. The star marks "
      "the largest ({} µm at line {}); the dotted rectangle is the stock. Hover for the program "
      "line, deflection and chatter margin.",
      shown.size(), engaged.size(), display(form[worst]), integer_text(at_or_nan(line, worst)));
  c.figures.push_back(std::move(f));
}

// ------------------------------------------------------------ the robot at its worst posture

/// A point [x, y, z] of summary.json, or false.
bool point_of(const json& value, std::vector<double>& out) {
  if (!value.is_array() || value.size() != 3)
    return false;
  out.clear();
  for (const json& v : value) {
    if (!v.is_number() || !std::isfinite(v.get<double>()))
      return false;
    out.push_back(v.get<double>());
  }
  return true;
}

void posture_figure(const json& along, Content& c) {
  const json posture = along.value("worst_posture", json());
  if (!posture.is_object())
    return;
  const json origins = posture.value("joint_origins_mm", json());
  if (!origins.is_array())
    return;
  std::vector<double> x, y, z, p;
  for (const json& o : origins)
    if (point_of(o, p))
      x.push_back(p[0]), y.push_back(p[1]), z.push_back(p[2]);
  if (x.size() < 2)
    return;
  std::vector<double> q;
  if (const json qs = posture.value("q_deg", json()); qs.is_array())
    for (const json& v : qs)
      q.push_back(v.is_number() ? v.get<double>() : std::nan(""));
  const double line = number_of(posture, "line");
  std::vector<double> tip;
  const bool has_tip = point_of(posture.value("tool_tip_mm", json()), tip);

  // Each point named: the joints (with their angle), the last the tool tip
  // when it is one, the base first.
  json names = json::array();
  for (std::size_t i = 0; i < x.size(); ++i) {
    std::string name = i == 0 ? "base" : fmt::format("frame {}", i);
    if (i < q.size())
      name =
          fmt::format("{}joint {}, q{} = {}°", i == 0 ? "base, " : "", i + 1, i + 1, display(q[i]));
    else if (i + 1 == x.size() && has_tip)
      name = "tool tip";
    names.push_back(name);
  }
  Figure f;
  f.title = std::isfinite(line)
                ? fmt::format("Robot at the worst posture, line {}", integer_text(line))
                : "Robot at the worst posture";
  json arm = {{"type", "scatter3d"},
              {"mode", "lines+markers"},
              {"name", "robot (joint origins)"},
              {"x", values(x)},
              {"y", values(y)},
              {"z", values(z)},
              {"text", names},
              {"line", {{"color", kRobotColor}, {"width", 9}}},
              {"marker", {{"color", "#f0a030"}, {"size", 5}, {"line", {{"color", kRobotColor}}}}},
              {"hovertemplate", "%{text}<br>x %{x} y %{y} z %{z} mm<extra></extra>"}};
  f.data.push_back(arm);
  json base = {{"type", "scatter3d"},
               {"mode", "markers"},
               {"name", "base"},
               {"x", values({x[0]})},
               {"y", values({y[0]})},
               {"z", values({z[0]})},
               {"marker", {{"color", kRobotColor}, {"symbol", "square"}, {"size", 9}}},
               {"hovertemplate", "base<extra></extra>"}};
  f.data.push_back(base);
  // The extent of the arm sets the tool axis's length (an eighth) and the
  // scene: a cube around everything drawn (a robot in the x-z plane has no
  // extent in y, which Plotly's "data" aspect would blow up).
  double extent = 0.0;
  for (const std::vector<double>* v : {&x, &y, &z}) {
    const auto [lo, hi] = finite_range(*v);
    extent = std::max(extent, hi - lo);
  }
  std::vector<double> all_x = x, all_y = y, all_z = z;
  if (has_tip) {
    f.data.push_back({{"type", "scatter3d"},
                      {"mode", "markers"},
                      {"name", "tool tip"},
                      {"x", values({tip[0]})},
                      {"y", values({tip[1]})},
                      {"z", values({tip[2]})},
                      {"marker", {{"color", kRiskColor}, {"symbol", "diamond"}, {"size", 7}}},
                      {"hovertemplate", "tool tip<br>x %{x} y %{y} z %{z} mm<extra></extra>"}});
    std::vector<double> axis;
    if (point_of(posture.value("tool_axis", json()), axis)) {
      const double norm = std::hypot(axis[0], axis[1], axis[2]);
      if (norm > 0.0) {
        const double length = std::max(50.0, 0.12 * extent) / norm;
        std::vector<double> ax, ay, az;
        for (double u : {0.0, 1.0}) {
          ax.push_back(tip[0] + u * length * axis[0]);
          ay.push_back(tip[1] + u * length * axis[1]);
          az.push_back(tip[2] + u * length * axis[2]);
        }
        all_x.insert(all_x.end(), ax.begin(), ax.end());
        all_y.insert(all_y.end(), ay.begin(), ay.end());
        all_z.insert(all_z.end(), az.begin(), az.end());
        f.data.push_back(
            {{"type", "scatter3d"},
             {"mode", "lines+markers"},
             {"name", "tool axis"},
             {"x", values(ax)},
             {"y", values(ay)},
             {"z", values(az)},
             {"line", {{"color", kRiskColor}, {"width", 6}}},
             {"marker",
              {{"color", kRiskColor}, {"size", json::array({2, 5})}, {"symbol", "circle"}}},
             {"hovertemplate",
              fmt::format("tool axis ({}, {}, {})<extra></extra>", display(axis[0] / norm),
                          display(axis[1] / norm), display(axis[2] / norm))}});
      }
    }
  }
  if (has_tip)
    all_x.push_back(tip[0]), all_y.push_back(tip[1]), all_z.push_back(tip[2]);
  double half = 50.0;
  for (const std::vector<double>* v : {&all_x, &all_y, &all_z}) {
    const auto [lo, hi] = finite_range(*v);
    half = std::max(half, 0.55 * (hi - lo));
  }
  auto scene_axis = [&](const std::vector<double>& v, const char* column) {
    const auto [lo, hi] = finite_range(v);
    const double middle = 0.5 * (lo + hi);
    return json{{"title", {{"text", axis_title(column)}}},
                {"range", {rounded(middle - half), rounded(middle + half)}}};
  };
  f.layout["scene"] = {{"xaxis", scene_axis(all_x, "x_mm")},
                       {"yaxis", scene_axis(all_y, "y_mm")},
                       {"zaxis", scene_axis(all_z, "z_mm")},
                       {"aspectmode", "cube"},
                       {"camera", camera()}};
  f.layout["margin"] = {{"l", 10}, {"r", 10}, {"t", 20}, {"b", 40}};
  f.layout["legend"] = {{"orientation", "h"}, {"y", -0.02}};
  f.height_px = 600;
  std::string angles;
  for (std::size_t i = 0; i < q.size(); ++i)
    angles += (i ? ", " : "") + display(q[i]);
  const std::string robot = along.value("robot", json()).is_string()
                                ? along["robot"].get<std::string>()
                                : std::string("The robot");
  f.caption = fmt::format(
      "{} at the posture of the sample with the smallest chatter margin{} (summary.json "
      "robot_along_path.worst_posture, cell frame): its joint frames' origins from the base to "
      "the tool tip joined by lines, the tool tip as a diamond and the tool axis from it. "
      "Hover for each joint's angle; drag to rotate. Axes are true to scale.",
      robot, q.empty() ? "" : fmt::format(", joint angles ({})°", angles));
  c.figures.push_back(std::move(f));
}

// ------------------------------------------------------------ tables

void headline_table(const json& along, Content& c) {
  TextTable table;
  table.title = "The robot along the path (summary.json robot_along_path)";
  table.header = {"result", "value", "line"};
  auto count = [&](const char* key, const std::string& label) {
    if (along.contains(key) && along[key].is_number())
      table.rows.push_back({label, json_text(along[key]), ""});
  };
  if (along.contains("robot") || along.contains("dof")) {
    const std::string name = json_text(along.value("robot", json()));
    const double dof = number_of(along, "dof");
    table.rows.push_back(
        {"robot", std::isfinite(dof) ? fmt::format("{}, {} axes", name, integer_text(dof)) : name,
         ""});
  }
  const double samples = number_of(along, "samples"),
               analysed = number_of(along, "analysed_samples");
  if (std::isfinite(analysed))
    table.rows.push_back({"samples analysed",
                          std::isfinite(samples) ? fmt::format("{} of {}", integer_text(analysed),
                                                               integer_text(samples))
                                                 : integer_text(analysed),
                          ""});
  count("unreachable_samples", "samples out of reach");
  count("joint_limit_samples", "samples at a joint limit");
  if (const double f = number_of(along, "fraction_at_risk"); std::isfinite(f))
    table.rows.push_back({"fraction at risk of chatter", display(100.0 * f) + " %", ""});
  count("chatter_samples", "samples with chatter");
  if (const double m = number_of(along, "min_margin"); std::isfinite(m))
    table.rows.push_back(
        {"smallest chatter margin", display(m), integer_text(number_of(along, "min_margin_line"))});
  if (const double e = number_of(along, "max_form_error_um"); std::isfinite(e))
    table.rows.push_back({"largest form error", display(e) + " µm",
                          integer_text(number_of(along, "max_form_error_line"))});
  if (const double d = number_of(along, "max_deflection_um"); std::isfinite(d))
    table.rows.push_back({"largest deflection", display(d) + " µm", ""});
  if (const json offset = along.value("offset", json()); offset.is_object()) {
    const double dm = number_of(offset, "dm_um"), max = number_of(offset, "max_um");
    if (std::isfinite(dm))
      table.rows.push_back(
          {fmt::format("004 offset d_m ({})", offset.value("measure", std::string("peak"))),
           display(dm) + " µm", ""});
    if (std::isfinite(max))
      table.rows.push_back({"largest 004 offset", display(max) + " µm",
                            integer_text(number_of(offset, "max_line"))});
  }
  count("dynamics_recomputations", "dynamics recomputations");
  if (const double e = number_of(along, "shortcut_max_error"); std::isfinite(e))
    table.rows.push_back({"shortcut's measured error", display(e), ""});
  if (!table.rows.empty())
    c.tables.push_back(std::move(table));
}

void worst_lines_table(const json& along, Content& c) {
  const json lines = along.value("worst_lines", json());
  if (!lines.is_array())
    return;
  TextTable table;
  table.title =
      "Program lines with the smallest chatter margin, and the advice (summary.json "
      "robot_along_path.worst_lines)";
  struct Column {
    const char* key;
    std::string header;
  };
  const std::vector<Column> columns = {{"line", "line"},
                                       {"t_s", axis_title("t_s")},
                                       {"margin", "chatter margin"},
                                       {"ap_mm", axis_title("ap_mm")},
                                       {"ap_limit_mm", "stable ap (mm)"},
                                       {"spindle_rpm", axis_title("spindle_rpm")},
                                       {"chatter_freq_hz", "chatter frequency (Hz)"},
                                       {"form_error_um", axis_title("form_error_um")},
                                       {"advice", "advice"}};
  for (const Column& column : columns)
    table.header.push_back(column.header);
  for (const json& item : lines) {
    if (!item.is_object())
      continue;
    std::vector<std::string> row;
    for (const Column& column : columns) {
      const json value = item.value(column.key, json());
      row.push_back(std::string(column.key) == "line" && value.is_number()
                        ? integer_text(value.get<double>())
                        : json_text(value));
    }
    table.rows.push_back(std::move(row));
  }
  if (table.rows.empty()) {
    table.rows.push_back(std::vector<std::string>(table.header.size(), "—"));
    table.rows.front().back() = "none";
  }
  c.tables.push_back(std::move(table));
}

// ------------------------------------------------------------ the better program

// --optimize's feeds: programmed and chosen feed per changed program line,
// coloured by the cap that set it, the loads before and after on hover.
void feed_figure(const json& feeds, Content& c) {
  const json changes = feeds.value("changes", json());
  if (!changes.is_array() || changes.empty())
    return;
  std::vector<double> lines, programmed, chosen;
  std::vector<std::string> binding, hover;
  for (const json& change : changes) {
    if (!change.is_object())
      continue;
    const double line = number_of(change, "line");
    const double from = number_of(change, "programmed_mm_min");
    const double to = number_of(change, "chosen_mm_min");
    if (!std::isfinite(line) || !std::isfinite(from) || !std::isfinite(to))
      continue;
    lines.push_back(line);
    programmed.push_back(from);
    chosen.push_back(to);
    binding.push_back(json_text(change.value("binding", json())));
    const json before = change.value("before", json::object());
    const json after = change.value("after", json::object());
    hover.push_back(fmt::format(
        "line {}: {} → {} mm/min ({})<br>peak force {} → {} N<br>peak torque {} → {} N·m<br>"
        "deflection {} → {} µm<br>fastest joint {} → {} °/s",
        integer_text(line), display(from), display(to), binding.back(),
        display(number_of(before, "force_peak_N")), display(number_of(after, "force_peak_N")),
        display(number_of(before, "torque_peak_Nm")), display(number_of(after, "torque_peak_Nm")),
        display(number_of(before, "deflection_um")), display(number_of(after, "deflection_um")),
        display(number_of(before, "joint_speed_deg_s")),
        display(number_of(after, "joint_speed_deg_s"))));
  }
  if (lines.empty())
    return;
  Figure f;
  f.title = "The better program: feed per program line";
  json was = trace(lines, programmed, "programmed feed", "markers");
  was["marker"] = {{"color", "#999999"}, {"symbol", "line-ew-open"}, {"size", 14}};
  was["hoverinfo"] = "skip";
  f.data.push_back(was);
  const std::vector<std::string> caps = {"force", "torque", "deflection", "joint_speed",
                                         "feed_max"};
  for (std::size_t k = 0; k < caps.size(); ++k) {
    std::vector<double> x, y;
    std::vector<std::string> text;
    for (std::size_t i = 0; i < lines.size(); ++i)
      if (binding[i] == caps[k]) {
        x.push_back(lines[i]);
        y.push_back(chosen[i]);
        text.push_back(hover[i]);
      }
    if (x.empty())
      continue;
    json now = trace(x, y, "chosen, set by " + caps[k], "markers");
    now["marker"] = {{"color", kColors[k % 8]}, {"size", 8}};
    now["text"] = text;
    now["hovertemplate"] = "%{text}<extra></extra>";
    f.data.push_back(now);
  }
  f.layout["xaxis"] = axis("program line");
  f.layout["yaxis"] = axis("feed (mm/min)");
  f.layout["legend"] = {{"orientation", "h"}, {"y", -0.2}};
  f.caption = fmt::format(
      "robomill toolpath --optimize under robot_path.feed_limits (summary.json "
      "optimization.feeds): each changed line's programmed feed (grey dash) and the feed "
      "written back, coloured by the cap that set it; hover gives the loads measured on runs "
      "of the whole program before and after. {} of {} feed lines changed in {} runs.",
      integer_text(number_of(feeds, "lines_changed")),
      integer_text(number_of(feeds, "lines_with_feed")), integer_text(number_of(feeds, "runs")));
  c.figures.push_back(std::move(f));
}

// --optimize's before and after, measured (the re-run of the written program).
void optimization_table(const json& optimization, const json& summary, Content& c) {
  TextTable table;
  table.title = "The better program (summary.json optimization)";
  table.header = {"result", "before", "after"};
  const json after = optimization.value("after", json::object());
  const json along = summary.value("robot_along_path", json::object());
  // Spindle speeds whole (12000 rpm, not 1.2e+04), the rest to 4 digits.
  auto text = [](double value, const std::string& unit) {
    if (!std::isfinite(value))
      return std::string("—");
    return (unit == " rpm" ? integer_text(value) : display(value)) + unit;
  };
  auto row = [&](const std::string& label, double before, double now, const std::string& unit) {
    if (std::isfinite(before) || std::isfinite(now))
      table.rows.push_back({label, text(before, unit), text(now, unit)});
  };
  table.rows.push_back({"program", json_text(summary.value("program", json())),
                        json_text(optimization.value("program", json()))});
  const json redundancy = optimization.value("redundancy", json());
  if (redundancy.is_object())
    row("redundancy angle ψ", number_of(redundancy, "programmed_deg"),
        number_of(redundancy, "chosen_deg"), " °");
  const json spindles = optimization.value("spindle_choices", json());
  if (spindles.is_array())
    for (const json& choice : spindles)
      if (choice.is_object() && choice.contains("lines") && choice["lines"].is_array() &&
          choice["lines"].size() == 2)
        row(fmt::format("spindle, lines {}-{}", json_text(choice["lines"][0]),
                        json_text(choice["lines"][1])),
            number_of(choice, "programmed_rpm"), number_of(choice, "chosen_rpm"), " rpm");
  row("smallest chatter margin", number_of(along, "min_margin"), number_of(after, "min_margin"),
      "");
  row("samples with chatter", number_of(along, "chatter_samples"),
      number_of(after, "chatter_samples"), "");
  // With uncertainty: the draws on both programs (the written one re-run
  // with every draw).
  const json drawn_before = along.value("uncertainty", json::object());
  const json drawn_after = after.value("uncertainty", json::object());
  if (drawn_after.is_object() && !drawn_after.empty()) {
    row("expected samples with chatter (draws)",
        number_of(drawn_before, "expected_chatter_samples"),
        number_of(drawn_after, "expected_chatter_samples"), "");
    row("highest P(chatter)", 100.0 * number_of(drawn_before, "max_p_chatter"),
        100.0 * number_of(drawn_after, "max_p_chatter"), " %");
    row("lines over the bound", number_of(drawn_before, "lines_over_bound_count"),
        number_of(drawn_after, "lines_over_bound_count"), "");
  }
  row("largest form error", number_of(along, "max_form_error_um"),
      number_of(after, "max_form_error_um"), " µm");
  row("largest peak force", number_of(summary, "max_force_N"), number_of(after, "max_force_N"),
      " N");
  row("largest peak torque", number_of(summary, "max_torque_Nm"), number_of(after, "max_torque_Nm"),
      " N·m");
  row("largest deflection", number_of(along, "max_deflection_um"),
      number_of(after, "max_deflection_um"), " µm");
  row("cycle time", number_of(optimization, "cycle_time_before_s"),
      number_of(after, "cycle_time_s"), " s");
  row("samples newly at risk", std::numeric_limits<double>::quiet_NaN(),
      number_of(optimization, "samples_newly_at_risk"), "");
  // The compensation: the walls' error at the feeds chosen, without and with
  // the moved path (both measured).
  if (const json compensation = optimization.value("compensation", json());
      compensation.is_object()) {
    const json before = compensation.value("form_error_before_um", json::object());
    const json residual = compensation.value("residual_um", json::object());
    for (const char* which : {"median", "p90", "max"})
      row(fmt::format("wall error, {} (compensated: after)", which), number_of(before, which),
          number_of(residual, which), " µm");
    table.rows.push_back({"compensation", "—",
                          fmt::format("{} lines moved, {} points added",
                                      integer_text(number_of(compensation, "lines_compensated")),
                                      integer_text(number_of(compensation, "points_added")))});
  }
  c.tables.push_back(std::move(table));
}

}  // namespace

void robot_path_colours(const Table& s, const std::vector<std::size_t>& feed_rows, Figure& f) {
  if (!s.has("margin") || f.data.empty() || !f.layout.contains("updatemenus"))
    return;
  json& feed = f.data[0];
  json& buttons = f.layout["updatemenus"][0]["buttons"];
  if (!feed.contains("customdata") || feed["customdata"].size() != feed_rows.size() ||
      !buttons.is_array())
    return;
  const std::vector<double> margin = s.numbers("margin"), ap_limit = s.numbers("ap_limit_mm"),
                            form = s.numbers("form_error_um");
  const bool has_form = s.has("form_error_um");
  // The colours along the feed trace; a gap repeats the value before it.
  std::vector<double> in_cut;
  for (std::size_t r : feed_rows)
    in_cut.push_back(at_or_nan(margin, r));
  const auto [m_low, m_high] = margin_range(in_cut);
  std::vector<double> c_margin, c_form;
  json& custom = feed["customdata"];
  for (std::size_t i = 0; i < feed_rows.size(); ++i) {
    const std::size_t r = feed_rows[i];
    if (r >= s.rows()) {
      c_margin.push_back(c_margin.empty() ? m_high : c_margin.back());
      c_form.push_back(c_form.empty() ? 0.0 : c_form.back());
      continue;
    }
    const double m = at_or_nan(margin, r), e = at_or_nan(form, r);
    c_margin.push_back(std::isfinite(m) ? m : m_high);  // not in the cut: stable
    c_form.push_back(std::isfinite(e) ? e : 0.0);
    custom[i].push_back(display(m));
    custom[i].push_back(display(at_or_nan(ap_limit, r)));
    custom[i].push_back(display(e));
  }
  std::string hover = feed.value("hovertemplate", std::string());
  const std::string added = "<br>chatter margin %{customdata[5]} (stable ap %{customdata[6]} mm)" +
                            std::string(has_form ? "<br>form error %{customdata[7]} µm" : "");
  std::size_t where = hover.find("<br>x %{x}");
  if (where == std::string::npos)
    where = std::min(hover.find("<extra>"), hover.size());
  hover.insert(where, added);
  feed["hovertemplate"] = hover;

  // Every button now sets its colour scale and range's bottom as well.
  const json scale = feed["marker"].value("colorscale", json("Viridis"));
  const json bottom = feed["marker"].value("cmin", json(0));
  for (json& button : buttons) {
    json& args = button["args"][0];
    args["marker.cmin"] = bottom;
    args["line.cmin"] = bottom;
    args["marker.colorscale"] = json::array({scale});
    args["line.colorscale"] = json::array({scale});
  }
  auto recolour = [](const std::string& label, const std::vector<double>& colour, double low,
                     double high, const json& colour_scale, const std::string& title) {
    return json{{"label", label},
                {"method", "restyle"},
                {"args", json::array({{{"marker.color", json::array({values(colour)})},
                                       {"line.color", json::array({values(colour)})},
                                       {"marker.cmin", rounded(low)},
                                       {"line.cmin", rounded(low)},
                                       {"marker.cmax", rounded(high)},
                                       {"line.cmax", rounded(high)},
                                       {"marker.colorscale", json::array({colour_scale})},
                                       {"line.colorscale", json::array({colour_scale})},
                                       {"marker.colorbar.title.text", title}},
                                      json::array({0})})}};
  };
  buttons.push_back(recolour("colour: chatter margin", c_margin, m_low, m_high, margin_scale(),
                             "chatter margin (ap limit / ap)"));
  if (has_form) {
    const auto [f_low, f_high] = form_range(c_form);
    buttons.push_back(recolour("colour: form error", c_form, f_low, f_high, kFormScale,
                               axis_title("form_error_um")));
  }
  f.caption +=
      " With the robot along the path, the menu also colours the path by the chatter margin "
      "(stable axial depth over the depth cut, diverging about 1: red below 1 is chatter; "
      "samples not in the cut drawn as stable)" +
      std::string(has_form ? " and by the form error (µm, positive where material is left)" : "") +
      "; hover adds the margin and the stable depth.";
}

void toolpath_robot_figures(const Table* s, const json& summary, Content& c) {
  if (s != nullptr && s->has("margin")) {
    robot_time_figure(*s, c);
    form_error_map(*s, summary, c);
  }
  const auto it = summary.find("robot_along_path");
  if (it == summary.end() || !it->is_object())
    return;
  posture_figure(*it, c);
  headline_table(*it, c);
  worst_lines_table(*it, c);
  path_uncertainty_figures(s, *it, c);
  const auto optimization = summary.find("optimization");
  if (optimization != summary.end() && optimization->is_object() &&
      optimization->value("changed", false)) {
    if (optimization->contains("feeds") && (*optimization)["feeds"].is_object())
      feed_figure((*optimization)["feeds"], c);
    optimization_table(*optimization, summary, c);
  }
}

}  // namespace robomill::report::detail
