// The report of `robomill toolpath`: the program's path in 3-D coloured by
// engagement or force, the engagement and loads over time with the program
// lines on hover, the final stock, the worst program lines and the warnings.
// Built from samples_preview.csv (the full samples.csv can be hundreds of MB
// and is never read here), moves.csv, stock.csv and summary.json.

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "detail.hpp"
#include "figure_helpers.hpp"

namespace robomill::report::detail {
namespace {

using nlohmann::json;

constexpr std::size_t kPathPoints = 20000;  // per 3-D trace (the preview holds at most this)
constexpr std::size_t kStockNodes = 200;    // per direction of the stock grid
constexpr std::size_t kWorstMoves = 10;
constexpr const char* kRapidColor = "#9aa3ad";
constexpr const char* kPeakColor = "#ff1493";

double summary_number(const json& summary, const std::string& key) {
  const auto it = summary.find(key);
  return it != summary.end() && it->is_number() ? it->get<double>() : std::nan("");
}

/// One number for the page: rounded, or null when not finite.
json number(double value) {
  return std::isfinite(value) ? json(rounded(value)) : json(nullptr);
}

/// The largest finite value (`fallback` when none is positive).
double largest(const std::vector<double>& v, double fallback) {
  double top = 0.0;
  for (double x : v)
    if (std::isfinite(x))
      top = std::max(top, x);
  return top > 0.0 ? top : fallback;
}

/// The index of the largest finite value, or v.size() when none is finite.
std::size_t index_of_largest(const std::vector<double>& v) {
  std::size_t best = v.size();
  for (std::size_t i = 0; i < v.size(); ++i)
    if (std::isfinite(v[i]) && (best == v.size() || v[i] > v[best]))
      best = i;
  return best;
}

}  // namespace

json integer(double value) {
  return std::isfinite(value) ? json(std::llround(value)) : json(nullptr);
}

json integers(const std::vector<double>& numbers) {
  json out = json::array();
  for (double v : numbers)
    out.push_back(integer(v));
  return out;
}

std::vector<std::size_t> envelope(const std::vector<double>& y, std::size_t limit) {
  if (y.size() <= limit)
    return thin(y.size(), limit);
  const std::size_t run = (2 * y.size() + limit - 1) / limit;
  std::vector<std::size_t> at;
  for (std::size_t start = 0; start < y.size(); start += run) {
    const std::size_t end = std::min(y.size(), start + run);
    std::size_t low = start, high = start;
    for (std::size_t i = start; i < end; ++i) {
      if (!std::isfinite(y[i]))
        continue;
      if (!std::isfinite(y[low]) || y[i] < y[low])
        low = i;
      if (!std::isfinite(y[high]) || y[i] > y[high])
        high = i;
    }
    at.push_back(std::min(low, high));
    if (high != low)
      at.push_back(std::max(low, high));
  }
  return at;
}

namespace {

// ------------------------------------------------------------ the path in 3-D

/// The feed moves of the path in 3-D, coloured by engagement (`colour`, up
/// to `top`), with the program line, engagement, depths and force on hover
/// (`custom`).
json feed_trace(const std::vector<double>& fx, const std::vector<double>& fy,
                const std::vector<double>& fz, const json& custom,
                const std::vector<double>& colour, double top, const std::string& title) {
  json colorbar = {{"title", {{"text", title}, {"side", "right"}}}, {"len", 0.8}};
  return {{"type", "scatter3d"},
          {"mode", "lines+markers"},
          {"name", "feed moves"},
          // (no legend entry: Plotly's legend cannot draw a line coloured by an
          // array and warns; the colour bar names the colouring)
          {"showlegend", false},
          {"x", values(fx)},
          {"y", values(fy)},
          {"z", values(fz)},
          {"customdata", custom},
          {"line",
           {{"color", values(colour)},
            {"colorscale", "Viridis"},
            {"cmin", 0},
            {"cmax", rounded(top)},
            {"width", 4}}},
          {"marker",
           {{"color", values(colour)},
            {"colorscale", "Viridis"},
            {"cmin", 0},
            {"cmax", rounded(top)},
            {"size", 2},
            {"showscale", true},
            {"colorbar", colorbar}}},
          {"hovertemplate",
           "line %{customdata[0]}<br>engagement %{customdata[1]:.3g}°<br>"
           "ap %{customdata[2]:.3g} mm, ae %{customdata[3]:.3g} mm<br>"
           "peak force %{customdata[4]:.4g} N<br>x %{x} y %{y} z %{z} mm<extra></extra>"}};
}

/// A button of the path's menu: recolours the feed moves (trace 0).
json recolour_button(const std::string& label, const std::vector<double>& colour, double top,
                     const std::string& title) {
  return json{{"label", label},
              {"method", "restyle"},
              {"args", json::array({{{"marker.color", json::array({values(colour)})},
                                     {"line.color", json::array({values(colour)})},
                                     {"marker.cmax", rounded(top)},
                                     {"line.cmax", rounded(top)},
                                     {"marker.colorbar.title.text", title}},
                                    json::array({0})})}};
}

/// The path of the preview's samples in 3-D: the feed moves as one trace
/// coloured by engagement (a menu recolours it by peak force), the rapids as
/// thin grey lines, the largest peak force as a marker.
void path_figure(const Table& s, const json& summary, Content& c) {
  const std::vector<std::size_t> at = thin(s.rows(), kPathPoints);
  const std::vector<double> x = pick(s.numbers("x_mm"), at), y = pick(s.numbers("y_mm"), at),
                            z = pick(s.numbers("z_mm"), at), line = pick(s.numbers("line"), at),
                            engagement = pick(s.numbers("engagement_deg"), at),
                            ap = pick(s.numbers("ap_mm"), at), ae = pick(s.numbers("ae_mm"), at),
                            force = pick(s.numbers("force_peak_N"), at);
  const std::vector<std::string>& motion = s.text("motion");
  std::vector<bool> rapid(at.size(), false);
  for (std::size_t k = 0; k < at.size(); ++k)
    rapid[k] = at[k] < motion.size() && motion[at[k]] == "rapid";

  // Feed moves, with a gap where a rapid intervenes; the colour arrays repeat
  // the last value across a gap (Plotly draws no segment there anyway).
  std::vector<double> fx, fy, fz, f_engagement, f_force;
  json custom = json::array();
  std::vector<std::size_t> feed_rows;  // the preview row of each feed point, s.rows() at a gap
  // Rapids, each run joined to the samples before and after it.
  std::vector<double> rx, ry, rz, r_line;
  std::size_t last_feed = at.size(), last_rapid = at.size();
  const double gap = std::nan("");
  for (std::size_t k = 0; k < at.size(); ++k) {
    if (!rapid[k]) {
      if (last_feed != at.size() && last_feed + 1 != k) {
        fx.push_back(gap), fy.push_back(gap), fz.push_back(gap);
        f_engagement.push_back(f_engagement.back()), f_force.push_back(f_force.back());
        custom.push_back(json::array());
        feed_rows.push_back(s.rows());
      }
      fx.push_back(x[k]), fy.push_back(y[k]), fz.push_back(z[k]);
      f_engagement.push_back(std::isfinite(engagement[k]) ? engagement[k] : 0.0);
      f_force.push_back(std::isfinite(force[k]) ? force[k] : 0.0);
      custom.push_back(json::array({integer(line[k]), number(engagement[k]), number(ap[k]),
                                    number(ae[k]), number(force[k])}));
      feed_rows.push_back(at[k]);
      last_feed = k;
    }
    const bool near_rapid =
        rapid[k] || (k > 0 && rapid[k - 1]) || (k + 1 < at.size() && rapid[k + 1]);
    if (near_rapid) {
      if (last_rapid != at.size() && last_rapid + 1 != k)
        rx.push_back(gap), ry.push_back(gap), rz.push_back(gap), r_line.push_back(gap);
      rx.push_back(x[k]), ry.push_back(y[k]), rz.push_back(z[k]), r_line.push_back(line[k]);
      last_rapid = k;
    }
  }
  if (fx.empty())
    return;

  const std::string engagement_title = axis_title("engagement_deg");
  const std::string force_title = "peak force (N)";
  const double engagement_top = largest(f_engagement, 1.0), force_top = largest(f_force, 1.0);
  const json feed = feed_trace(fx, fy, fz, custom, f_engagement, engagement_top, engagement_title);
  Figure f;
  f.title = "Tool path";
  f.data.push_back(feed);
  if (!rx.empty()) {
    json rapids = {{"type", "scatter3d"},
                   {"mode", "lines"},
                   {"name", "rapids"},
                   {"x", values(rx)},
                   {"y", values(ry)},
                   {"z", values(rz)},
                   {"customdata", integers(r_line)},
                   {"line", {{"color", kRapidColor}, {"width", 1.5}}},
                   {"hovertemplate", "rapid, line %{customdata}<extra></extra>"}};
    f.data.push_back(rapids);
  }
  const std::size_t peak = index_of_largest(force);
  if (peak < at.size() && force[peak] > 0.0) {
    json marker = {
        {"type", "scatter3d"},
        {"mode", "markers"},
        {"name", "largest peak force"},
        {"x", values({x[peak]})},
        {"y", values({y[peak]})},
        {"z", values({z[peak]})},
        {"marker", {{"color", kPeakColor}, {"symbol", "diamond"}, {"size", 7}}},
        {"hovertemplate", fmt::format("largest peak force {} N<br>line {}<extra></extra>",
                                      display(force[peak]), integer_text(line[peak]))}};
    f.data.push_back(marker);
  }
  // The menu recolours the feed moves (trace 0): engagement or peak force.
  f.layout["updatemenus"] = json::array(
      {{{"type", "dropdown"},
        {"buttons",
         json::array(
             {recolour_button("colour: engagement", f_engagement, engagement_top, engagement_title),
              recolour_button("colour: peak force", f_force, force_top, force_title)})},
        {"x", 0},
        {"xanchor", "left"},
        {"y", 1.06},
        {"yanchor", "top"},
        {"showactive", true}}});
  f.layout["scene"] = {{"xaxis", {{"title", {{"text", axis_title("x_mm")}}}}},
                       {"yaxis", {{"title", {{"text", axis_title("y_mm")}}}}},
                       {"zaxis", {{"title", {{"text", axis_title("z_mm")}}}}},
                       {"aspectmode", "data"},
                       {"camera", camera()}};
  f.layout["margin"] = {{"l", 10}, {"r", 10}, {"t", 40}, {"b", 40}};
  f.layout["legend"] = {{"orientation", "h"}, {"y", -0.02}};
  f.height_px = 640;
  const double total = summary_number(summary, "samples");
  f.caption = fmt::format(
      "The tool-tip path of the program (workpiece frame; {} samples{} from "
      "samples_preview.csv), coloured by the cutter's engagement angle, or by the peak cutting "
      "force with the menu; rapids are thin grey lines, the diamond marks the largest peak "
      "force. Hover for the program line, engagement, axial and radial depth of cut and force; "
      "drag to rotate, scroll to zoom. Axes are true to scale.",
      at.size(), std::isfinite(total) ? fmt::format(" of {}", integer_text(total)) : "");
  robot_path_colours(s, feed_rows, f);  // chatter margin and form error, with the robot
  c.figures.push_back(std::move(f));
}

// ------------------------------------------------------------ over time

void time_figure(const Table& s, const json& summary, Content& c) {
  if (!s.has("t_s"))
    return;
  const std::vector<double> t = s.numbers("t_s"), line = s.numbers("line");
  Figure f;
  f.title = "Engagement and loads over time";
  stack(f, axis_title("t_s"),
        {axis_title("engagement_deg"), "depth of cut (mm)", "force (N)", axis_title("torque_Nm"),
         axis_title("power_W")},
        {1.0, 1.0, 1.4, 1.0, 1.0});
  f.height_px = 1000;
  f.layout["hovermode"] = "x unified";
  f.layout["legend"] = {{"orientation", "h"}, {"y", -0.09}};  // under the time axis's title
  struct Series {
    const char* column;
    const char* name;
    const char* unit;
    int row;
  };
  static constexpr Series series[] = {
      {"engagement_deg", "engagement", "°", 0}, {"ap_mm", "axial depth ap", "mm", 1},
      {"ae_mm", "radial depth ae", "mm", 1},    {"force_peak_N", "peak force", "N", 2},
      {"force_mean_N", "mean force", "N", 2},   {"torque_peak_Nm", "peak torque", "N·m", 3},
      {"torque_Nm", "torque", "N·m", 3},        {"power_W", "power", "W", 4}};
  std::size_t k = 0;
  for (const Series& item : series) {
    if (!s.has(item.column))
      continue;
    const std::vector<double> v = s.numbers(item.column);
    const std::vector<std::size_t> at = envelope(v, kTimePoints);
    json tr = trace(pick(t, at), pick(v, at), item.name);
    tr["customdata"] = integers(pick(line, at));
    tr["hovertemplate"] =
        fmt::format("{} %{{y:.4g}} {} (line %{{customdata}})<extra></extra>", item.name, item.unit);
    tr["line"] = {{"color", kColors[k++ % 8]}, {"width", 1.2}};
    f.data.push_back(on_row(tr, item.row));
  }
  if (f.data.empty())
    return;
  // The largest peak force of the preview, on the force row and across all.
  const std::vector<double> force = s.numbers("force_peak_N");
  const std::size_t peak = index_of_largest(force);
  if (peak < force.size() && force[peak] > 0.0 && std::isfinite(t[peak])) {
    json star = trace({t[peak]}, {force[peak]}, "largest peak force", "markers");
    star["marker"] = {{"color", kPeakColor}, {"symbol", "star"}, {"size", 14}};
    star["hovertemplate"] = fmt::format("largest peak force %{{y:.4g}} N (line {})<extra></extra>",
                                        integer_text(line[peak]));
    f.data.push_back(on_row(star, 2));
    f.layout["shapes"] =
        json::array({{{"type", "line"},
                      {"xref", "x"},
                      {"yref", "paper"},
                      {"x0", rounded(t[peak])},
                      {"x1", rounded(t[peak])},
                      {"y0", 0},
                      {"y1", 1},
                      {"line", {{"color", "#888"}, {"dash", "dot"}, {"width", 1}}}}});
    f.layout["annotations"] =
        json::array({{{"x", rounded(t[peak])},
                      {"xref", "x"},
                      {"y", 1},
                      {"yref", "paper"},
                      {"text", "largest force, line " + integer_text(line[peak])},
                      {"showarrow", false},
                      {"yanchor", "bottom"},
                      {"font", {{"size", 11}, {"color", "#555"}}}}});
  }
  const double max_force = summary_number(summary, "max_force_N");
  f.caption =
      "Per sample of samples_preview.csv over the program's time: the cutter's engagement angle, "
      "the axial (ap) and radial (ae) depth of cut, the peak and mean cutting force, the spindle "
      "torque and power; zero where the tool cuts air or moves rapid. Hover shows the program "
      "line of each sample; the star and the dotted line mark the largest peak force shown" +
      (std::isfinite(max_force)
           ? fmt::format(" (over every sample, summary.json: {} N at line {})", display(max_force),
                         json_text(summary.value("max_force_line", json())))
           : std::string()) +
      ". Long series keep the smallest and largest value of each run of samples.";
  c.figures.push_back(std::move(f));
}

// ------------------------------------------------------------ the stock

/// Nodes 0, k, 2k, ... and the last (the stock's far edge).
std::vector<std::size_t> every_kth(std::size_t count, std::size_t k) {
  std::vector<std::size_t> at;
  for (std::size_t i = 0; i < count; i += k)
    at.push_back(i);
  if (!at.empty() && at.back() != count - 1)
    at.push_back(count - 1);
  return at;
}

void stock_figures(const Table& t, const json& summary, Content& c) {
  if (!t.has("x_mm") || !t.has("y_mm") || !t.has("z_mm") || t.rows() == 0) {
    c.notes.push_back("stock.csv has no x_mm, y_mm, z_mm rows: the stock figures are left out.");
    return;
  }
  const std::vector<double> xs = t.numbers("x_mm"), ys = t.numbers("y_mm"), zs = t.numbers("z_mm");
  const std::vector<double> x_levels = levels_of(xs), y_levels = levels_of(ys);
  if (x_levels.size() < 2 || y_levels.size() < 2)
    return;
  // One stride in both directions keeps the grid regular and square.
  const std::size_t k =
      (std::max(x_levels.size(), y_levels.size()) + kStockNodes - 1) / kStockNodes;
  const std::vector<std::size_t> keep_x = every_kth(x_levels.size(), k),
                                 keep_y = every_kth(y_levels.size(), k);
  std::vector<std::ptrdiff_t> column(x_levels.size(), -1), row(y_levels.size(), -1);
  for (std::size_t i = 0; i < keep_x.size(); ++i)
    column[keep_x[i]] = static_cast<std::ptrdiff_t>(i);
  for (std::size_t i = 0; i < keep_y.size(); ++i)
    row[keep_y[i]] = static_cast<std::ptrdiff_t>(i);
  std::vector<std::vector<double>> grid(keep_y.size(),
                                        std::vector<double>(keep_x.size(), std::nan("")));
  auto level = [](const std::vector<double>& levels, double v) {
    return static_cast<std::size_t>(std::lower_bound(levels.begin(), levels.end(), rounded(v)) -
                                    levels.begin());
  };
  double z_low = std::numeric_limits<double>::infinity(), z_high = -z_low;
  for (std::size_t r = 0; r < t.rows(); ++r) {
    if (!std::isfinite(xs[r]) || !std::isfinite(ys[r]))
      continue;
    const std::ptrdiff_t i = column[level(x_levels, xs[r])], j = row[level(y_levels, ys[r])];
    if (i < 0 || j < 0)
      continue;
    grid[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)] = zs[r];
    if (std::isfinite(zs[r]))
      z_low = std::min(z_low, zs[r]), z_high = std::max(z_high, zs[r]);
  }
  if (!(z_high >= z_low))
    return;
  json matrix = json::array();
  for (const auto& g : grid)
    matrix.push_back(values(g));
  const json x_json = values(pick(x_levels, keep_x)), y_json = values(pick(y_levels, keep_y));
  const std::string z_title = axis_title("z_mm");
  const std::string shown =
      k == 1 ? fmt::format("every node of the {} × {} grid", x_levels.size(), y_levels.size())
             : fmt::format("one node in {} along x and y of the {} × {} grid", k, x_levels.size(),
                           y_levels.size());
  const double resolution = summary.contains("stock") && summary["stock"].is_object()
                                ? summary_number(summary["stock"], "resolution_mm")
                                : std::nan("");
  const std::string spacing =
      std::isfinite(resolution) ? fmt::format(", dexel spacing {} mm", display(resolution)) : "";

  Figure map = xy_figure("Final stock, height map", axis_title("x_mm"), axis_title("y_mm"));
  map.caption = fmt::format(
      "Height of the stock's top after the program over x and y (stock.csv, {}{}); x and y "
      "at the same scale. Hover for the height at a node.",
      shown, spacing);
  map.data.push_back({{"type", "heatmap"},
                      {"name", "stock height"},
                      {"x", x_json},
                      {"y", y_json},
                      {"z", matrix},
                      {"colorscale", "Viridis"},
                      {"hoverongaps", false},
                      {"hovertemplate", "x %{x} mm<br>y %{y} mm<br>z %{z:.4g} mm<extra></extra>"},
                      {"colorbar", {{"title", {{"text", z_title}, {"side", "right"}}}}}});
  map.layout["yaxis"]["scaleanchor"] = "x";
  map.layout["yaxis"]["scaleratio"] = 1;
  map.layout["xaxis"]["constrain"] = "domain";
  map.height_px = 560;
  c.figures.push_back(std::move(map));

  // The same grid in 3-D: x and y true to scale, heights at most slightly
  // exaggerated (to a tenth of the stock's extent, at most five times).
  const double x_span = x_levels.back() - x_levels.front(),
               y_span = y_levels.back() - y_levels.front();
  const double extent = std::max(x_span, y_span);
  const double relief = (z_high - z_low) / extent;
  const double exaggeration = relief < 0.1 ? std::min(5.0, relief > 0.0 ? 0.1 / relief : 5.0) : 1.0;
  Figure surface;
  surface.title = "Final stock, 3-D view";
  surface.caption = fmt::format(
      "The stock's top surface after the program ({}); x and y true to scale, heights drawn {}. "
      "Drag to rotate, scroll to zoom.",
      shown,
      exaggeration > 1.0 ? fmt::format("{:.1f} times exaggerated", exaggeration) : "to scale");
  surface.data.push_back(
      {{"type", "surface"},
       {"name", "stock"},
       {"x", x_json},
       {"y", y_json},
       {"z", matrix},
       {"colorscale", "Viridis"},
       {"hovertemplate", "x %{x} mm<br>y %{y} mm<br>z %{z:.4g} mm<extra></extra>"},
       {"colorbar", {{"title", {{"text", z_title}, {"side", "right"}}}}}});
  surface.layout["scene"] = {{"xaxis", {{"title", {{"text", axis_title("x_mm")}}}}},
                             {"yaxis", {{"title", {{"text", axis_title("y_mm")}}}}},
                             {"zaxis", {{"title", {{"text", z_title}}}}},
                             {"aspectmode", "manual"},
                             {"camera", camera()},
                             {"aspectratio",
                              {{"x", rounded(x_span / extent)},
                               {"y", rounded(y_span / extent)},
                               {"z", rounded(std::max(0.02, relief * exaggeration))}}}};
  surface.layout["margin"] = {{"l", 10}, {"r", 10}, {"t", 20}, {"b", 20}};
  surface.height_px = 600;
  c.figures.push_back(std::move(surface));
}

// ------------------------------------------------------------ tables

/// The moves with the largest cutting force, largest first.
void worst_moves_table(const Table& m, Content& c) {
  if (!m.has("max_force_N"))
    return;
  const std::vector<double> force = m.numbers("max_force_N");
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < force.size(); ++i)
    if (std::isfinite(force[i]) && force[i] > 0.0)
      order.push_back(i);
  const std::size_t shown = std::min(kWorstMoves, order.size());
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(shown), order.end(),
                    [&](std::size_t a, std::size_t b) { return force[a] > force[b]; });
  order.resize(shown);
  TextTable table;
  table.title = fmt::format(
      "The {} moves with the largest cutting force (moves.csv: maxima over each move's samples)",
      shown);
  // (column, header, integer): headers from the column names, units included.
  struct Column {
    std::string name, header;
    bool integer;
  };
  const std::vector<Column> columns = {
      {"line", "line", true},
      {"move", "move", true},
      {"tool", "tool", false},
      {"motion", "motion", false},
      {"max_force_N", axis_title("max_force_N"), false},
      {"max_torque_Nm", axis_title("max_torque_Nm"), false},
      {"max_power_W", axis_title("max_power_W"), false},
      {"max_engagement_deg", axis_title("max_engagement_deg"), false},
      {"max_ap_mm", axis_title("max_ap_mm"), false},
      {"max_ae_mm", axis_title("max_ae_mm"), false},
      {"removed_mm3", axis_title("removed_mm3"), false},
      {"feed_mm_min", "feed (mm/min)", false},
      {"spindle_rpm", axis_title("spindle_rpm"), false}};
  std::vector<const Column*> present;
  for (const Column& column : columns)
    if (m.has(column.name)) {
      present.push_back(&column);
      table.header.push_back(column.header);
    }
  for (std::size_t r : order) {
    std::vector<std::string> cells;
    for (const Column* column : present) {
      const std::string& text = m.text(column->name)[r];
      if (column->name == "tool" || column->name == "motion")
        cells.push_back(text);
      else {
        const double v = m.numbers(column->name)[r];
        cells.push_back(column->integer ? integer_text(v) : display(v));
      }
    }
    table.rows.push_back(std::move(cells));
  }
  if (table.rows.empty())
    table.rows.push_back(
        std::vector<std::string>(table.header.size(), "—"));  // no move cut: keep the header
  c.tables.push_back(std::move(table));
}

/// summary.json's list of {line, text[, count]} as a table (the key-results
/// table shows only scalars).
void list_table(const json& summary, const std::string& key, const std::string& title,
                const std::string& what, bool counted, Content& c) {
  const auto it = summary.find(key);
  if (it == summary.end() || !it->is_array())
    return;
  TextTable table{title, {"line", what}, {}};
  if (counted)
    table.header.push_back("count");
  for (const json& item : *it) {
    if (!item.is_object())
      continue;
    std::vector<std::string> row = {json_text(item.value("line", json())),
                                    json_text(item.value("text", json()))};
    if (counted)
      row.push_back(json_text(item.value("count", json(1))));
    table.rows.push_back(std::move(row));
  }
  if (table.rows.empty())
    table.rows.push_back(std::vector<std::string>(table.header.size(), "—"));
  if (table.rows.size() == 1 && it->empty())
    table.rows.front()[1] = "none";
  c.tables.push_back(std::move(table));
}

}  // namespace

void toolpath_figures(const Outputs& o, Content& c) {
  const auto s = o.table("samples_preview.csv", c);
  if (s) {
    path_figure(*s, o.summary, c);
    time_figure(*s, o.summary, c);
  }
  toolpath_robot_figures(s ? &*s : nullptr, o.summary, c);
  if (const auto t = o.table("stock.csv", c))
    stock_figures(*t, o.summary, c);
  // Only the rows the table shows: a long program's moves.csv is larger
  // than the rest of the report's data together.
  if (const auto m = o.largest_rows("moves.csv", "max_force_N", kWorstMoves, c))
    worst_moves_table(*m, c);
  list_table(o.summary, "warnings", "Warnings of the analysis (summary.json)", "warning", true, c);
  if (o.summary.contains("notes") && o.summary["notes"].is_array() && !o.summary["notes"].empty())
    list_table(o.summary, "notes", "Notes of the program reader (summary.json)", "note", false, c);
}

}  // namespace robomill::report::detail
