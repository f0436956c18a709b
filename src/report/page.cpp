// report.html's page: tables, axis titles and the HTML around the figures.

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <map>
#include <string>
#include <utility>

#include "detail.hpp"
#include "robomill/core/error.hpp"
#include "robomill/report/report.hpp"

namespace robomill::report {
namespace detail {

// ---------------------------------------------------------------- tables

namespace {

std::vector<std::string> split_line(std::string_view line) {
  std::vector<std::string> cells;
  std::string cell;
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        cell += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cell += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      cells.push_back(std::move(cell));
      cell.clear();
    } else if (c != '\r') {
      cell += c;
    }
  }
  cells.push_back(std::move(cell));
  return cells;
}

double parse_number(const std::string& text) {
  if (text.empty())
    return std::nan("");
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size())
    return std::nan("");
  return value;
}

}  // namespace

namespace {

// Calls on_header(cells) for the first row (comment lines starting with '#'
// before it skipped) and on_row(cells) for each later non-empty row; either
// returning false stops the reading. False when a callback stopped it.
template <class OnHeader, class OnRow>
bool for_each_row(std::string_view text, OnHeader&& on_header, OnRow&& on_row) {
  std::size_t start = 0;
  bool header = true;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos)
      end = text.size();
    const std::string_view line = text.substr(start, end - start);
    start = end + 1;
    if (line.empty() || line == "\r")
      continue;
    if (header && line.front() == '#')
      continue;
    std::vector<std::string> cells = split_line(line);
    if (header) {
      header = false;
      if (!on_header(cells))
        return false;
    } else if (!on_row(cells)) {
      return false;
    }
  }
  return true;
}

}  // namespace

std::optional<Table> Table::parse(std::string_view text) {
  Table table;
  const bool read = for_each_row(
      text,
      [&](std::vector<std::string>& cells) {
        table.names_ = std::move(cells);
        table.cells_.resize(table.names_.size());
        return true;
      },
      [&](std::vector<std::string>& cells) {
        if (cells.size() != table.names_.size())
          return false;
        for (std::size_t c = 0; c < cells.size(); ++c)
          table.cells_[c].push_back(std::move(cells[c]));
        ++table.rows_;
        return true;
      });
  if (!read || table.names_.empty())
    return std::nullopt;
  return table;
}

std::optional<Table> Table::parse_largest(std::string_view text, const std::string& column,
                                          std::size_t rows) {
  Table table;
  std::size_t key = 0, row = 0;
  bool has_key = true;
  // The kept rows: (value, row), a min-heap on the value (the later row
  // first among equal ones), and their cells.
  std::vector<std::pair<double, std::size_t>> heap;
  std::map<std::size_t, std::vector<std::string>> kept;
  const auto smaller = [](const std::pair<double, std::size_t>& a,
                          const std::pair<double, std::size_t>& b) {
    return a.first > b.first || (a.first == b.first && a.second < b.second);
  };
  const bool read = for_each_row(
      text,
      [&](std::vector<std::string>& cells) {
        table.names_ = std::move(cells);
        const auto it = std::find(table.names_.begin(), table.names_.end(), column);
        has_key = it != table.names_.end();
        key = static_cast<std::size_t>(it - table.names_.begin());
        table.cells_.resize(table.names_.size());
        return has_key;
      },
      [&](std::vector<std::string>& cells) {
        if (cells.size() != table.names_.size())
          return false;
        const double value = parse_number(cells[key]);
        const std::size_t index = row++;
        if (!std::isfinite(value) || rows == 0)
          return true;
        if (heap.size() == rows) {
          if (!(value > heap.front().first))
            return true;
          std::pop_heap(heap.begin(), heap.end(), smaller);
          kept.erase(heap.back().second);
          heap.pop_back();
        }
        heap.emplace_back(value, index);
        std::push_heap(heap.begin(), heap.end(), smaller);
        kept.emplace(index, std::move(cells));
        return true;
      });
  if (!has_key)  // no such column: the whole table
    return parse(text);
  if (!read || table.names_.empty())
    return std::nullopt;
  for (auto& [index, cells] : kept) {
    for (std::size_t c = 0; c < cells.size(); ++c)
      table.cells_[c].push_back(std::move(cells[c]));
    ++table.rows_;
  }
  return table;
}

bool Table::has(const std::string& column) const {
  return std::find(names_.begin(), names_.end(), column) != names_.end();
}

const std::vector<std::string>& Table::text(const std::string& column) const {
  static const std::vector<std::string> none;
  const auto it = std::find(names_.begin(), names_.end(), column);
  return it == names_.end() ? none : cells_[static_cast<std::size_t>(it - names_.begin())];
}

std::vector<double> Table::numbers(const std::string& column) const {
  const std::vector<std::string>& cells = text(column);
  std::vector<double> out;
  out.reserve(cells.size());
  for (const std::string& cell : cells)
    out.push_back(parse_number(cell));
  return out;
}

Table Table::where(const std::string& column, const std::string& value) const {
  Table out;
  out.names_ = names_;
  out.cells_.resize(names_.size());
  const std::vector<std::string>& key = text(column);
  for (std::size_t r = 0; r < key.size(); ++r) {
    if (key[r] != value)
      continue;
    for (std::size_t c = 0; c < names_.size(); ++c)
      out.cells_[c].push_back(cells_[c][r]);
    ++out.rows_;
  }
  return out;
}

std::vector<std::string> Table::distinct(const std::string& column) const {
  std::vector<std::string> out;
  for (const std::string& cell : text(column))
    if (std::find(out.begin(), out.end(), cell) == out.end())
      out.push_back(cell);
  return out;
}

bool Table::any_nonzero(const std::string& column) const {
  for (double v : numbers(column))
    if (std::isfinite(v) && v != 0.0)
      return true;
  return false;
}

// ---------------------------------------------------------------- units

namespace {

// Unit tokens of column names (DESIGN.md §4: units in column names).
const std::map<std::string, std::string>& unit_tokens() {
  static const std::map<std::string, std::string> units = {
      {"rpm", "rpm"}, {"mm", "mm"}, {"um", "µm"},   {"m", "m"},     {"hz", "Hz"},    {"Hz", "Hz"},
      {"s", "s"},     {"N", "N"},   {"Nm", "N·m"},  {"deg", "°"},   {"rad", "rad"},  {"pct", "%"},
      {"kg", "kg"},   {"W", "W"},   {"mm2", "mm²"}, {"m2", "m²"},   {"cm3", "cm³"},  {"min", "min"},
      {"mm3", "mm³"}, {"J", "J"},   {"Pa", "Pa"},   {"MPa", "MPa"}, {"N_m2", "N·m²"}};
  return units;
}

std::vector<std::string> tokens_of(const std::string& column) {
  std::vector<std::string> tokens;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = column.find('_', start);
    tokens.push_back(column.substr(start, end - start));
    if (end == std::string::npos)
      break;
    start = end + 1;
  }
  return tokens;
}

// How many trailing tokens form the unit, and the unit's display text.
std::pair<std::size_t, std::string> unit_of(const std::vector<std::string>& tokens) {
  const auto& units = unit_tokens();
  const std::size_t n = tokens.size();
  auto unit = [&](const std::string& token) -> std::optional<std::string> {
    const auto it = units.find(token);
    if (it == units.end())
      return std::nullopt;
    return it->second;
  };
  // X_per_Y (N_per_m, um_per_N, cm3_per_min), also Nm_per_rad.
  if (n >= 4 && tokens[n - 2] == "per") {
    const auto num = unit(tokens[n - 3]), den = unit(tokens[n - 1]);
    if (num && den)
      return {3, *num + "/" + *den};
  }
  // N_m2 (flexural rigidity).
  if (n >= 3 && tokens[n - 2] == "N" && tokens[n - 1] == "m2")
    return {2, "N·m²"};
  if (n >= 2) {
    if (const auto u = unit(tokens[n - 1]))
      return {1, *u};
  }
  return {0, ""};
}

const std::map<std::string, std::string>& quantity_names() {
  static const std::map<std::string, std::string> names = {
      {"spindle", "spindle speed"},
      {"depth limit", "limiting depth"},
      {"chatter freq", "chatter frequency"},
      {"freq", "frequency"},
      {"t", "time"},
      {"fx", "Fx"},
      {"fy", "Fy"},
      {"fz", "Fz"},
      {"fn", "natural frequency"},
      {"lowest fn", "lowest natural frequency"},
      {"mrr", "material removal rate"},
      {"ap", "axial depth ap"},
      {"ae", "radial depth ae"},
      {"dm", "mean tool offset dm"},
      {"max", "largest tool offset"},
      {"zeta", "damping ratio ζ"},
      {"k", "modal stiffness k"},
      {"m", "modal mass m"},
      {"limit depth", "limiting depth"},
      {"min limit", "minimum limiting depth"},
      {"depth min", "minimum limiting depth"},
      {"depth max", "maximum limiting depth"},
      {"redundancy", "redundancy angle"},
      {"feed per tooth", "feed per tooth"},
      {"dx", "deflection x"},
      {"dy", "deflection y"},
      {"dz", "deflection z"},
      {"z", "z"},
  };
  return names;
}

}  // namespace

std::string column_unit(const std::string& column) {
  return unit_of(tokens_of(column)).second;
}

std::string column_quantity(const std::string& column) {
  const std::vector<std::string> tokens = tokens_of(column);
  const std::size_t unit_tokens_count = unit_of(tokens).first;
  std::string quantity;
  for (std::size_t i = 0; i + unit_tokens_count < tokens.size(); ++i)
    quantity += (i ? " " : "") + tokens[i];
  const auto& names = quantity_names();
  const auto it = names.find(quantity);
  return it == names.end() ? quantity : it->second;
}

std::string axis_title(const std::string& column) {
  const std::string unit = column_unit(column);
  const std::string quantity = column_quantity(column);
  return unit.empty() ? quantity : quantity + " (" + unit + ")";
}

// ---------------------------------------------------------------- numbers

double rounded(double value) {
  if (!std::isfinite(value) || value == 0.0)
    return value;
  char buffer[32];
  const auto result =
      std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::general, 6);
  double out = value;
  std::from_chars(buffer, result.ptr, out);
  return out;
}

nlohmann::json values(const std::vector<double>& numbers) {
  nlohmann::json out = nlohmann::json::array();
  for (double v : numbers) {
    if (std::isfinite(v))
      out.push_back(rounded(v));
    else
      out.push_back(nullptr);
  }
  return out;
}

std::vector<std::size_t> thin(std::size_t count, std::size_t limit) {
  std::vector<std::size_t> at;
  if (count == 0)
    return at;
  const std::size_t stride = count <= limit ? 1 : (count + limit - 1) / limit;
  for (std::size_t i = 0; i < count; i += stride)
    at.push_back(i);
  if (at.back() != count - 1)
    at.push_back(count - 1);
  return at;
}

std::vector<double> pick(const std::vector<double>& numbers, const std::vector<std::size_t>& at) {
  std::vector<double> out;
  out.reserve(at.size());
  for (std::size_t i : at)
    out.push_back(i < numbers.size() ? numbers[i] : std::nan(""));
  return out;
}

std::string display(double value) {
  if (!std::isfinite(value))
    return "—";
  return fmt::format("{:.4g}", value);
}

// ---------------------------------------------------------------- figures

nlohmann::json trace(const std::vector<double>& x, const std::vector<double>& y,
                     const std::string& name, const std::string& mode) {
  return {{"type", "scatter"}, {"mode", mode}, {"name", name}, {"x", values(x)}, {"y", values(y)}};
}

nlohmann::json axis(const std::string& title, bool log) {
  nlohmann::json a = {{"title", {{"text", title}}}, {"automargin", true}, {"zeroline", false}};
  if (log) {
    a["type"] = "log";
    a["exponentformat"] = "power";
    a["dtick"] = 1;  // a label per decade, not the 2 and 5 between
  }
  return a;
}

Figure xy_figure(const std::string& title, const std::string& x_title, const std::string& y_title) {
  Figure figure;
  figure.title = title;
  figure.layout["xaxis"] = axis(x_title);
  figure.layout["yaxis"] = axis(y_title);
  return figure;
}

void stack(Figure& figure, const std::string& x_title, const std::vector<std::string>& y_titles,
           const std::vector<double>& weights) {
  const std::size_t rows = y_titles.size();
  std::vector<double> w = weights.size() == rows ? weights : std::vector<double>(rows, 1.0);
  double total = 0.0;
  for (double v : w)
    total += v;
  const double gap = rows > 1 ? 0.07 : 0.0;
  const double usable = 1.0 - gap * static_cast<double>(rows - 1);
  double top = 1.0;
  for (std::size_t r = 0; r < rows; ++r) {
    const double height = usable * w[r] / total;
    const double bottom = std::max(0.0, top - height);
    const std::string suffix = r == 0 ? std::string() : fmt::format("{}", r + 1);
    nlohmann::json y = axis(y_titles[r]);
    y["domain"] = {rounded(bottom), rounded(top)};
    y["anchor"] = fmt::format("x{}", suffix);
    nlohmann::json x = axis(r + 1 == rows ? x_title : "");
    x["anchor"] = fmt::format("y{}", suffix);
    if (r > 0)
      x["matches"] = "x";
    if (r + 1 < rows)
      x["showticklabels"] = false;
    // Keep any earlier settings (log axes) of these axes.
    // (A named copy: items() of a temporary would outlive it in the loop.)
    const nlohmann::json earlier = figure.layout.value("yaxis" + suffix, nlohmann::json::object());
    for (const auto& [key, value] : earlier.items())
      y[key] = value;
    figure.layout["yaxis" + suffix] = y;
    figure.layout["xaxis" + suffix] = x;
    top = bottom - gap;
  }
  figure.height_px = static_cast<int>(260 + 200 * rows);
}

nlohmann::json& on_row(nlohmann::json& t, int row) {
  if (row > 0) {
    t["xaxis"] = fmt::format("x{}", row + 1);
    t["yaxis"] = fmt::format("y{}", row + 1);
  }
  return t;
}

std::optional<Table> Outputs::table(const std::string& name, Content& content,
                                    bool required) const {
  const auto it = files.find(name);
  if (it == files.end()) {
    if (required)
      content.notes.push_back(name + " is not in the output folder: its figures are left out.");
    return std::nullopt;
  }
  std::optional<Table> parsed = Table::parse(it->second);
  if (!parsed)
    content.notes.push_back(name + " could not be read as a CSV table: its figures are left out.");
  return parsed;
}

std::optional<Table> Outputs::largest_rows(const std::string& name, const std::string& column,
                                           std::size_t rows, Content& content) const {
  const auto it = files.find(name);
  if (it == files.end()) {
    content.notes.push_back(name + " is not in the output folder: its figures are left out.");
    return std::nullopt;
  }
  std::optional<Table> parsed = Table::parse_largest(it->second, column, rows);
  if (!parsed)
    content.notes.push_back(name + " could not be read as a CSV table: its figures are left out.");
  return parsed;
}

}  // namespace detail

// ---------------------------------------------------------------- the page

namespace {

using detail::Content;
using detail::Figure;

std::string escape_html(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// JSON inside <script>: "</" would close the element early.
std::string script_safe(std::string json) {
  std::string out;
  out.reserve(json.size());
  for (std::size_t i = 0; i < json.size(); ++i) {
    if (json[i] == '<' && i + 1 < json.size() && json[i + 1] == '/')
      out += "<\\";
    else
      out += json[i];
  }
  return out;
}

std::string scalar_text(const nlohmann::json& value) {
  if (value.is_number_float())
    return detail::display(value.get<double>());
  if (value.is_number())
    return value.dump();
  if (value.is_boolean())
    return value.get<bool>() ? "yes" : "no";
  if (value.is_string())
    return value.get<std::string>();
  if (value.is_null())
    return "—";
  return value.dump();
}

bool is_short_list(const nlohmann::json& value) {
  if (!value.is_array() || value.empty() || value.size() > 8)
    return false;
  for (const auto& item : value)
    if (!item.is_primitive())
      return false;
  return true;
}

// The summary's key figures: scalars, short lists and one level of objects
// of scalars (mean_N.x), with the unit read from the key.
void flatten(const nlohmann::json& object, const std::string& prefix,
             std::vector<std::vector<std::string>>& rows, int depth) {
  for (const auto& [key, value] : object.items()) {
    if (depth == 0 && (key == "command" || key == "job" || key == "name"))
      continue;
    const std::string name = prefix.empty() ? key : prefix + "." + key;
    std::string unit = detail::column_unit(key);
    if (unit.empty() && !prefix.empty())
      unit = detail::column_unit(prefix);  // mean_N.x
    if (value.is_primitive()) {
      rows.push_back({name, scalar_text(value), unit});
    } else if (is_short_list(value)) {
      std::string text;
      for (std::size_t i = 0; i < value.size(); ++i)
        text += (i ? ", " : "") + scalar_text(value[i]);
      rows.push_back({name, text, unit});
    } else if (value.is_object() && depth < 1) {
      flatten(value, name, rows, depth + 1);
    }
  }
}

void table_html(std::string& html, const detail::TextTable& table, const char* css_class) {
  html += fmt::format("<table class=\"{}\">", css_class);
  if (!table.title.empty())
    html += "<caption>" + escape_html(table.title) + "</caption>";
  html += "<thead><tr>";
  for (const std::string& h : table.header)
    html += "<th>" + escape_html(h) + "</th>";
  html += "</tr></thead><tbody>";
  for (const auto& row : table.rows) {
    html += "<tr>";
    for (const std::string& cell : row)
      html += "<td>" + escape_html(cell) + "</td>";
    html += "</tr>";
  }
  html += "</tbody></table>\n";
}

constexpr const char* kStyle = R"css(
:root { --ink: #1d2733; --muted: #5b6775; --line: #d9dee5; --accent: #1f5fa8; }
* { box-sizing: border-box; }
body { margin: 0; font: 15px/1.45 system-ui, -apple-system, "Segoe UI", Roboto, sans-serif;
       color: var(--ink); background: #f6f7f9; }
header { background: #16324f; color: #fff; padding: 18px 28px; }
header h1 { margin: 0 0 4px; font-size: 22px; }
header p { margin: 0; color: #c9d6e5; }
main { max-width: 1180px; margin: 0 auto; padding: 12px 24px 40px; }
h2 { font-size: 18px; margin: 26px 0 10px; border-bottom: 2px solid var(--line); padding-bottom: 4px; }
.columns { display: flex; flex-wrap: wrap; gap: 24px; align-items: flex-start; }
.columns > div { flex: 1 1 420px; min-width: 0; }
table { border-collapse: collapse; background: #fff; font-size: 13.5px; width: 100%; margin-bottom: 14px; }
caption { text-align: left; font-weight: 600; padding: 4px 0; }
th, td { border: 1px solid var(--line); padding: 4px 8px; text-align: left; vertical-align: top; }
th { background: #eef1f5; }
td.group { color: var(--muted); white-space: nowrap; }
.data { display: block; overflow-x: auto; white-space: nowrap; }
figure { margin: 0 0 22px; background: #fff; border: 1px solid var(--line); border-radius: 6px; padding: 8px 10px; }
figure h3 { margin: 2px 4px 0; font-size: 16px; }
figcaption { color: var(--muted); font-size: 13px; margin: 2px 4px 4px; }
.plot { width: 100%; }
.note { color: #8a5a00; background: #fff7e0; border: 1px solid #f0dca0; padding: 6px 10px; border-radius: 4px; }
footer { color: var(--muted); font-size: 12.5px; margin-top: 28px; }
)css";

constexpr const char* kScript = R"js(
(function () {
  var figures = JSON.parse(document.getElementById('robomill-figures').textContent);
  var config = { responsive: true, displaylogo: false,
                 toImageButtonOptions: { format: 'png', scale: 2 } };
  figures.forEach(function (figure, i) {
    var layout = figure.layout;
    layout.margin = layout.margin || { l: 70, r: 30, t: 30, b: 60 };
    layout.legend = layout.legend || { orientation: 'h', y: -0.18 };
    layout.font = { family: 'system-ui, sans-serif', size: 13 };
    layout.height = figure.height;
    Plotly.newPlot('figure-' + i, figure.data, layout, config);
  });
})();
)js";

}  // namespace

std::string render_html(const Files& files) {
  const auto summary_file = files.find("summary.json");
  if (summary_file == files.end())
    throw InputError("summary.json", 0,
                     "not found: a report is built from a command's output folder, which holds "
                     "summary.json");
  nlohmann::json summary = nlohmann::json::parse(summary_file->second, nullptr, false);
  if (summary.is_discarded() || !summary.is_object())
    throw InputError("summary.json", 0, "is not a JSON object");
  const std::string command = summary.value("command", std::string("unknown"));

  detail::Outputs outputs{files, summary, command};
  Content content = detail::build_content(outputs);

  nlohmann::json inputs;
  if (const auto it = files.find("inputs.json"); it != files.end()) {
    inputs = nlohmann::json::parse(it->second, nullptr, false);
    if (inputs.is_discarded())
      inputs = nullptr;
  }
  std::string name = summary.value("name", std::string());
  if (name.empty() && inputs.is_object())
    name = inputs.value("name", std::string());
  std::string job = summary.value("job", std::string());
  if (job.empty() && inputs.is_object())
    job = inputs.value("job", std::string());

  std::string html;
  html.reserve(plotly_js().size() + (1u << 20));
  html += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  html += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  html += "<meta name=\"generator\" content=\"robomill 0.1.0\">\n";
  html += "<title>" + escape_html("robomill " + command + (name.empty() ? "" : " — " + name)) +
          "</title>\n<style>" + kStyle + "</style>\n";
  // Plotly, inlined: the page needs nothing else.
  html += "<script>";
  html += plotly_js();
  html += "</script>\n</head>\n<body>\n<header><h1>";
  html += escape_html("robomill " + command);
  html += "</h1><p>";
  html += escape_html(name.empty() ? job : name + (job.empty() ? "" : " — " + job));
  html += "</p></header>\n<main>\n";

  // Key inputs and key results side by side.
  html += "<div class=\"columns\">\n";
  if (inputs.is_object() && inputs.contains("inputs") && inputs["inputs"].is_array() &&
      !inputs["inputs"].empty()) {
    html +=
        "<div><h2>Key inputs</h2><table class=\"inputs\"><thead><tr><th>section</th>"
        "<th>input</th><th>value</th></tr></thead><tbody>";
    std::string last_group;
    for (const auto& row : inputs["inputs"]) {
      if (!row.is_object())
        continue;
      const std::string group = row.value("group", std::string());
      html += "<tr><td class=\"group\">" + escape_html(group == last_group ? "" : group) +
              "</td><td>" + escape_html(row.value("name", std::string())) + "</td><td>" +
              escape_html(row.value("value", std::string())) + "</td></tr>";
      last_group = group;
    }
    html += "</tbody></table></div>\n";
  }
  std::vector<std::vector<std::string>> key_rows;
  flatten(summary, "", key_rows, 0);
  html += "<div><h2>Key results</h2>";
  table_html(html, {"", {"result", "value", "unit"}, key_rows}, "results");
  html += "</div>\n</div>\n";

  for (const std::string& note : content.notes)
    html += "<p class=\"note\">" + escape_html(note) + "</p>\n";

  nlohmann::json figures = nlohmann::json::array();
  if (!content.figures.empty()) {
    html += "<h2>Figures</h2>\n";
    for (std::size_t i = 0; i < content.figures.size(); ++i) {
      const Figure& f = content.figures[i];
      html += fmt::format("<figure><h3>{}</h3>", escape_html(f.title));
      if (!f.caption.empty())
        html += "<figcaption>" + escape_html(f.caption) + "</figcaption>";
      html += fmt::format(
          "<div class=\"plot\" id=\"figure-{}\" data-title=\"{}\" style=\"height:{}px\"></div>"
          "</figure>\n",
          i, escape_html(f.title), f.height_px);
      figures.push_back({{"data", f.data}, {"layout", f.layout}, {"height", f.height_px}});
    }
  }
  if (!content.tables.empty()) {
    html += "<h2>Tables</h2>\n";
    for (const detail::TextTable& t : content.tables)
      table_html(html, t, "data");
  }
  html += "<footer>Files in this output folder: ";
  bool first = true;
  for (const auto& [file, text] : files) {
    html += (first ? "" : ", ") + escape_html(file);
    first = false;
  }
  html +=
      ". Written by robomill 0.1.0; rebuild with <code>robomill report FOLDER</code>. "
      "Plots by Plotly (MIT), embedded.</footer>\n</main>\n";
  html += "<script type=\"application/json\" id=\"robomill-figures\">";
  html += script_safe(figures.dump());
  html += "</script>\n<script>";
  html += kScript;
  html += "</script>\n</body>\n</html>\n";
  return html;
}

}  // namespace robomill::report
