// The figures of each command's report, from the files the command writes
// (DESIGN.md §3's output table; the column names carry the units).

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <string>

#include "detail.hpp"
#include "figure_helpers.hpp"
#include "robomill/io/uff58.hpp"

namespace robomill::report::detail {

std::vector<double> levels_of(const std::vector<double>& v) {
  std::set<double> s;
  for (double x : v)
    if (std::isfinite(x))
      s.insert(rounded(x));
  return {s.begin(), s.end()};
}

namespace {

using nlohmann::json;

constexpr std::size_t kMaxPoints = 4000;  // per trace: plenty for a screen, small pages

/// A column with the rows whose `reachable` column is 0 as gaps.
std::vector<double> reachable_only(const Table& t, const std::string& column) {
  std::vector<double> v = t.numbers(column);
  if (t.has("reachable")) {
    const std::vector<double> reachable = t.numbers("reachable");
    for (std::size_t i = 0; i < v.size(); ++i)
      if (reachable[i] == 0.0)
        v[i] = std::nan("");
  }
  return v;
}

}  // namespace

const char* color(std::size_t i) {
  return kColors[i % 8];
}

nlohmann::json line_trace(const std::vector<double>& x, const std::vector<double>& y,
                          const std::string& name, std::size_t color_index,
                          const std::string& dash) {
  const std::vector<std::size_t> at = thin(x.size(), kMaxPoints);
  json t = trace(pick(x, at), pick(y, at), name);
  t["line"] = {{"color", color(color_index)}, {"width", 1.6}, {"dash", dash}};
  return t;
}

nlohmann::json marker_trace(const std::vector<double>& x, const std::vector<double>& y,
                            const std::string& name, const std::string& marker_color,
                            const std::string& symbol, double size) {
  const std::vector<std::size_t> at = thin(x.size(), kMaxPoints);
  json t = trace(pick(x, at), pick(y, at), name, "markers");
  t["marker"] = {{"color", marker_color}, {"symbol", symbol}, {"size", size}};
  return t;
}

std::vector<double> positive_or_gap(std::vector<double> v) {
  for (double& x : v)
    if (!(x > 0.0))
      x = std::nan("");
  return v;
}

double summary_number(const nlohmann::json& summary, const std::string& key,
                      const std::string& sub) {
  const json* node = &summary;
  if (!node->contains(key))
    return std::nan("");
  node = &(*node)[key];
  if (!sub.empty()) {
    if (!node->is_object() || !node->contains(sub))
      return std::nan("");
    node = &(*node)[sub];
  }
  return node->is_number() ? node->get<double>() : std::nan("");
}

namespace {

// ------------------------------------------------------------ grid maps

struct Axis {
  std::string column;
  std::vector<double> levels;  // sorted distinct values
};

std::size_t level_index(const std::vector<double>& levels, double v) {
  const auto it = std::lower_bound(levels.begin(), levels.end(), rounded(v));
  return static_cast<std::size_t>(it - levels.begin());
}

std::string level_label(const std::string& column, double value) {
  const std::string unit = column_unit(column);
  return column_quantity(column) + " = " + display(value) + (unit.empty() ? "" : " " + unit);
}

}  // namespace

std::optional<Figure> grid_map(const Table& t, const std::vector<std::string>& coords,
                               const std::string& value, const std::string& title,
                               const std::string& mask) {
  if (!t.has(value) || t.rows() == 0)
    return std::nullopt;
  std::vector<double> z = t.numbers(value);
  if (t.has(mask)) {
    const std::vector<double> m = t.numbers(mask);
    for (std::size_t i = 0; i < z.size(); ++i)
      if (!(m[i] != 0.0))
        z[i] = std::nan("");
  }
  bool any = false;
  for (double v : z)
    any = any || std::isfinite(v);
  if (!any)
    return std::nullopt;
  std::vector<Axis> varying;
  for (const std::string& c : coords) {
    if (!t.has(c))
      continue;
    Axis a{c, levels_of(t.numbers(c))};
    if (a.levels.size() > 1)
      varying.push_back(std::move(a));
  }
  if (varying.empty())
    return std::nullopt;
  Figure figure;
  figure.title = title;
  if (varying.size() == 1) {
    figure.layout["xaxis"] = axis(axis_title(varying[0].column));
    figure.layout["yaxis"] = axis(axis_title(value));
    figure.data.push_back(
        marker_trace(t.numbers(varying[0].column), z, column_quantity(value), color(0)));
    figure.data.back()["mode"] = "lines+markers";
    return figure;
  }
  const Axis& ax = varying[0];
  const Axis& ay = varying[1];
  const std::vector<double> xs = t.numbers(ax.column), ys = t.numbers(ay.column);
  // Facets: the combinations of the remaining varying coordinates.
  std::vector<std::vector<double>> facet_values;
  for (std::size_t k = 2; k < varying.size(); ++k)
    facet_values.push_back(t.numbers(varying[k].column));
  std::map<std::vector<double>, std::vector<std::size_t>> facets;
  for (std::size_t r = 0; r < t.rows(); ++r) {
    std::vector<double> key;
    for (const auto& f : facet_values)
      key.push_back(rounded(f[r]));
    facets[key].push_back(r);
  }
  const std::size_t max_facets = 24;
  std::size_t index = 0;
  json buttons = json::array();
  for (const auto& [key, rows] : facets) {
    if (index == max_facets)
      break;
    json matrix = json::array();
    std::vector<std::vector<double>> grid(ay.levels.size(),
                                          std::vector<double>(ax.levels.size(), std::nan("")));
    for (std::size_t r : rows) {
      if (!std::isfinite(xs[r]) || !std::isfinite(ys[r]))
        continue;
      grid[level_index(ay.levels, ys[r])][level_index(ax.levels, xs[r])] = z[r];
    }
    for (const auto& row : grid)
      matrix.push_back(values(row));
    std::string label;
    for (std::size_t k = 0; k < key.size(); ++k)
      label += (k ? ", " : "") + level_label(varying[k + 2].column, key[k]);
    json heat = {{"type", "heatmap"},
                 {"x", values(ax.levels)},
                 {"y", values(ay.levels)},
                 {"z", matrix},
                 {"colorscale", "Viridis"},
                 {"name", label.empty() ? column_quantity(value) : label},
                 {"hoverongaps", false},
                 {"colorbar", {{"title", {{"text", axis_title(value)}, {"side", "right"}}}}},
                 {"visible", index == 0}};
    figure.data.push_back(heat);
    buttons.push_back({{"label", label}, {"method", "restyle"}});
    ++index;
  }
  if (index > 1) {
    for (std::size_t b = 0; b < index; ++b) {
      json visible = json::array();
      for (std::size_t k = 0; k < index; ++k)
        visible.push_back(k == b);
      buttons[b]["args"] = json::array({{{"visible", visible}}, json::array()});
      for (std::size_t k = 0; k < index; ++k)
        buttons[b]["args"][1].push_back(k);
    }
    figure.layout["updatemenus"] = json::array({{{"type", "dropdown"},
                                                 {"buttons", buttons},
                                                 {"x", 0},
                                                 {"xanchor", "left"},
                                                 {"y", 1.14},
                                                 {"yanchor", "top"},
                                                 {"showactive", true}}});
    figure.caption = "Choose the " + column_quantity(varying[2].column) +
                     (varying.size() > 3 ? " (and the other coordinates)" : "") +
                     " with the menu above the map.";
    figure.layout["margin"] = {{"l", 70}, {"r", 30}, {"t", 60}, {"b", 60}};
  }
  figure.layout["xaxis"] = axis(axis_title(ax.column));
  figure.layout["yaxis"] = axis(axis_title(ay.column));
  figure.height_px = 520;
  return figure;
}

namespace {

// ------------------------------------------------------------ FRFs

struct Curve {
  std::string name;
  std::vector<double> frequency_hz;
  std::vector<std::complex<double>> value;
  bool markers = false;
};

/// Indices of at most about `limit` samples of an increasing positive grid,
/// evenly spaced in log frequency (dense where a log axis needs them).
std::vector<std::size_t> thin_log(const std::vector<double>& f, std::size_t limit) {
  std::vector<std::size_t> at;
  double last = 0.0;
  double ratio = 1.0;
  for (double x : f)
    if (x > 0.0 && std::isfinite(x)) {
      ratio = std::pow(f.back() / x, 1.0 / static_cast<double>(limit));
      break;
    }
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (!(f[i] > 0.0))
      continue;
    if (at.empty() || f[i] >= last * ratio || i + 1 == f.size()) {
      at.push_back(i);
      last = f[i];
    }
  }
  return at;
}

/// Magnitude (log) over phase (deg) of several FRFs; a log frequency axis
/// when the grid spans more than two decades (robot modes at 20 Hz next to
/// the tool's at 4 kHz).
Figure bode(const std::string& title, const std::vector<Curve>& curves,
            const std::string& magnitude_unit) {
  Figure figure;
  figure.title = title;
  stack(figure, "frequency (Hz)", {"magnitude (" + magnitude_unit + ")", "phase (°)"}, {2.0, 1.0});
  double f_low = std::numeric_limits<double>::infinity(), f_high = 0.0;
  for (const Curve& curve : curves)
    for (double x : curve.frequency_hz)
      if (x > 0.0 && std::isfinite(x))
        f_low = std::min(f_low, x), f_high = std::max(f_high, x);
  const bool log_x = f_high > 100.0 * f_low;
  if (log_x) {
    figure.layout["xaxis"]["type"] = figure.layout["xaxis2"]["type"] = "log";
    figure.layout["xaxis2"]["exponentformat"] = "power";
  }
  figure.layout["yaxis"]["type"] = "log";
  figure.layout["yaxis"]["exponentformat"] = "power";
  figure.layout["yaxis"]["dtick"] = 1;
  for (std::size_t c = 0; c < curves.size(); ++c) {
    const Curve& curve = curves[c];
    const std::vector<std::size_t> at = log_x ? thin_log(curve.frequency_hz, kMaxPoints)
                                              : thin(curve.frequency_hz.size(), kMaxPoints);
    std::vector<double> f, mag, phase;
    for (std::size_t i : at) {
      f.push_back(curve.frequency_hz[i]);
      mag.push_back(std::abs(curve.value[i]));
      phase.push_back(std::arg(curve.value[i]) * 180.0 / std::numbers::pi);
    }
    // Unwrapped, so that noise around ±180° does not draw a jump of 360°.
    for (std::size_t i = 1; i < phase.size(); ++i) {
      while (phase[i] - phase[i - 1] > 180.0)
        phase[i] -= 360.0;
      while (phase[i] - phase[i - 1] < -180.0)
        phase[i] += 360.0;
    }
    mag = positive_or_gap(mag);
    json m = trace(f, mag, curve.name, curve.markers ? "markers" : "lines");
    json p = trace(f, phase, curve.name, curve.markers ? "markers" : "lines");
    for (json* t : {&m, &p}) {
      // Measured: a broad pale band; fitted or synthesized: a thin line on it.
      if (curve.markers) {
        (*t)["mode"] = "lines";
        (*t)["line"] = {{"color", "#7fa7d6"}, {"width", 5}};
        (*t)["opacity"] = 0.75;
      } else {
        (*t)["line"] = {{"color", color(curves.size() == 2 && c == 1 ? 1 : c)}, {"width", 1.6}};
      }
      (*t)["legendgroup"] = curve.name;
    }
    p["showlegend"] = false;
    figure.data.push_back(m);
    figure.data.push_back(on_row(p, 1));
  }
  return figure;
}

// ------------------------------------------------------------ commands

}  // namespace

void experiments_overlay(const Outputs& o, Figure& f) {
  const json* tests = nullptr;
  if (o.summary.contains("experiments") && o.summary["experiments"].is_object() &&
      o.summary["experiments"].contains("tests") && o.summary["experiments"]["tests"].is_array())
    tests = &o.summary["experiments"]["tests"];
  if (!tests || tests->empty())
    return;
  for (int chatter = 0; chatter < 2; ++chatter) {
    std::vector<double> x, y;
    json text = json::array();
    for (const json& test : *tests) {
      if (!test.is_object() || test.value("observed_chatter", false) != (chatter == 1))
        continue;
      x.push_back(test.value("spindle_rpm", std::nan("")));
      y.push_back(test.value("depth_mm", std::nan("")));
      text.push_back(fmt::format("predicted: {}; {}",
                                 test.value("predicted_chatter", false) ? "chatter" : "stable",
                                 test.value("agrees", false) ? "agrees" : "disagrees"));
    }
    if (x.empty())
      continue;
    json t = chatter ? marker_trace(x, y, "test: chatter observed", "#d62728", "x", 11)
                     : marker_trace(x, y, "test: stable observed", "#2ca02c", "circle", 10);
    t["text"] = text;
    t["marker"]["line"] = {{"width", 1.5}, {"color", chatter ? "#7a0000" : "#0b5d0b"}};
    f.data.push_back(t);
  }
  f.caption += " Markers: the job's cutting tests (green circles stable, red crosses chatter).";
}

namespace {

void stability(const Outputs& o, Content& c) {
  const auto sld = o.table("sld.csv", c, false);
  const auto envelope = o.table("sld_envelope.csv", c, false);
  const auto map = o.table("map.csv", c, false);
  if (sld && sld->has("spindle_rpm")) {
    Figure f;
    f.title = "Stability lobe diagram";
    f.caption = fmt::format(
        "Limiting axial depth over spindle speed ({}); cuts below the line are "
        "stable. Lower panel: chatter frequency at the limit.",
        o.summary.value("method", std::string("?")));
    stack(f, "spindle speed (rpm)", {"limiting depth (mm)", "chatter frequency (Hz)"}, {2.2, 1.0});
    const std::vector<double> rpm = sld->numbers("spindle_rpm");
    std::size_t k = 0;
    for (const std::string& col : sld->columns()) {
      if (col.rfind("depth_limit", 0) != 0)
        continue;
      std::string name =
          col == "depth_limit_mm" ? "limiting depth" : "limit, " + column_quantity(col.substr(12));
      f.data.push_back(line_trace(rpm, sld->numbers(col), name, k));
      const std::string freq_col = col == "depth_limit_mm"
                                       ? "chatter_freq_hz"
                                       : "chatter_freq_" + col.substr(12, col.size() - 15) + "_hz";
      if (sld->has(freq_col)) {
        json fr = marker_trace(rpm, sld->numbers(freq_col), name, color(k), "circle", 4);
        fr["showlegend"] = false;
        fr["legendgroup"] = name;
        f.data.back()["legendgroup"] = name;
        f.data.push_back(on_row(fr, 1));
      }
      ++k;
    }
    if (envelope && envelope->has("depth_limit_mm")) {
      const std::vector<double> erpm = envelope->numbers("spindle_rpm");
      f.data.push_back(line_trace(erpm, envelope->numbers("depth_limit_mm"),
                                  "envelope of single modes", 7, "dash"));
      f.data.back()["legendgroup"] = "envelope";
      json fr = marker_trace(erpm, envelope->numbers("chatter_freq_hz"), "envelope of single modes",
                             color(7), "diamond", 4);
      fr["showlegend"] = false;
      fr["legendgroup"] = "envelope";
      f.data.push_back(on_row(fr, 1));
    }
    experiments_overlay(o, f);
    c.figures.push_back(std::move(f));
  } else if (!map) {
    c.notes.push_back("sld.csv is not in the output folder: the lobe diagram is left out.");
  }
  if (map) {
    if (auto m = grid_map(*map, {"spindle_rpm", "depth_mm"}, "spectral_radius",
                          "Stability map: spectral radius")) {
      m->caption =
          "Spectral radius of the monodromy operator over speed and depth: below 1 "
          "stable (blue), above 1 chatter (red). The line is the limiting depth.";
      for (auto& t : m->data)
        t["zmin"] = 0.0, t["zmax"] = 2.0, t["colorscale"] = "RdBu",
        t["colorbar"]["title"]["text"] = "spectral radius (colours clipped at 2)";
      if (sld && sld->has("depth_limit_mm")) {
        json line = line_trace(sld->numbers("spindle_rpm"), sld->numbers("depth_limit_mm"),
                               "limiting depth", 0);
        line["line"]["color"] = "#000";
        m->data.push_back(line);
      }
      experiments_overlay(o, *m);
      c.figures.push_back(std::move(*m));
    }
  }
  stability_band_figures(o, c);
}

void fit_modes(const Outputs& o, Content& c) {
  if (const auto fit = o.table("frf_fit.csv", c)) {
    for (const std::string& name : fit->distinct("frf")) {
      const Table part = fit->where("frf", name);
      const std::vector<double> f = part.numbers("freq_hz");
      const std::vector<double> mr = part.numbers("measured_re"), mi = part.numbers("measured_im");
      const std::vector<double> fr = part.numbers("fitted_re"), fi = part.numbers("fitted_im");
      Curve measured{"measured " + name, f, {}, true}, fitted{"fitted " + name, f, {}, false};
      for (std::size_t i = 0; i < f.size(); ++i) {
        measured.value.emplace_back(mr[i], mi[i]);
        fitted.value.emplace_back(fr[i], fi[i]);
      }
      Figure b = bode("FRF " + name + ": measured and fitted", {measured, fitted}, "m/N");
      b.caption =
          "Receptance magnitude (log) and phase: measured points and the fitted modal "
          "model.";
      c.figures.push_back(std::move(b));
    }
  }
  if (const auto stab = o.table("stabilization.csv", c, false)) {
    const auto fit = o.table("frf_fit.csv", c, false);
    for (const std::string& name : stab->distinct("frf")) {
      const Table part = stab->where("frf", name);
      Figure f = xy_figure("Stabilization diagram " + name, "frequency (Hz)", "model order");
      f.caption =
          "Poles of the rational-fraction fits per model order: stable in frequency and "
          "damping (filled), in frequency only (open), not stable (dots). Grey: the "
          "measured magnitude.";
      const std::vector<double> freq = part.numbers("freq_hz"), order = part.numbers("order");
      const std::vector<double> sf = part.numbers("stable_frequency"),
                                sd = part.numbers("stable_damping");
      struct Class {
        const char* name;
        const char* symbol;
        const char* color;
        int level;
      };
      for (const Class& cls : {Class{"stable frequency and damping", "circle", "#1f77b4", 2},
                               Class{"stable frequency", "circle-open", "#ff7f0e", 1},
                               Class{"new pole", "circle", "#bbbbbb", 0}}) {
        std::vector<double> x, y;
        for (std::size_t i = 0; i < freq.size(); ++i) {
          const int level = sf[i] == 1.0 ? (sd[i] == 1.0 ? 2 : 1) : 0;
          if (level == cls.level) {
            x.push_back(freq[i]);
            y.push_back(order[i]);
          }
        }
        if (!x.empty())
          f.data.push_back(marker_trace(x, y, cls.name, cls.color, cls.symbol, cls.level ? 6 : 3));
      }
      if (fit) {
        const Table m = fit->where("frf", name);
        const std::vector<double> mf = m.numbers("freq_hz"), re = m.numbers("measured_re"),
                                  im = m.numbers("measured_im");
        std::vector<double> mag;
        for (std::size_t i = 0; i < mf.size(); ++i)
          mag.push_back(std::hypot(re[i], im[i]));
        json t = line_trace(mf, positive_or_gap(mag), "measured |H|", 0);
        t["line"]["color"] = "#999";
        t["yaxis"] = "y2";
        f.data.push_back(t);
        json y2 = axis("measured magnitude (m/N)", true);
        y2["overlaying"] = "y";
        y2["side"] = "right";
        y2["showgrid"] = false;
        f.layout["yaxis2"] = y2;
      }
      c.figures.push_back(std::move(f));
    }
  }
}

void frf(const Outputs& o, Content& c) {
  const std::string kind = o.summary.value("kind", std::string("receptance"));
  const std::string unit = kind == "mobility"      ? "m/(s·N)"
                           : kind == "accelerance" ? "m/(s²·N)"
                                                   : "m/N";
  std::vector<Curve> curves;
  for (const auto& [name, text] : o.files) {
    if (name.size() > 4 && (name.ends_with(".uff") || name.ends_with(".unv"))) {
      try {
        for (const io::UffFrf& u : io::parse_uff58(text, name)) {
          const char* axes = "xyz";
          curves.push_back(
              {fmt::format("H{}{}", axes[u.frf.response_axis], axes[u.frf.reference_axis]),
               u.frf.frequency_hz, u.frf.value, false});
        }
      } catch (const std::exception& error) {
        c.notes.push_back(name + " could not be read: " + error.what());
      }
    } else if (name.starts_with("frf") && name.ends_with(".csv")) {
      const auto t = Table::parse(text);
      if (!t || !t->has("freq_hz"))
        continue;
      Curve curve{name.substr(0, name.size() - 4), t->numbers("freq_hz"), {}, false};
      if (t->has("re")) {
        const auto re = t->numbers("re"), im = t->numbers("im");
        for (std::size_t i = 0; i < re.size(); ++i)
          curve.value.emplace_back(re[i], im[i]);
      } else if (t->has("mag")) {
        const auto mag = t->numbers("mag"), ph = t->numbers("phase_deg");
        for (std::size_t i = 0; i < mag.size(); ++i)
          curve.value.push_back(std::polar(mag[i], ph[i] * std::numbers::pi / 180.0));
      } else {
        continue;
      }
      curves.push_back(std::move(curve));
    }
  }
  if (curves.empty()) {
    c.notes.push_back("No FRF file (frf.uff, frf_*.csv) in the output folder.");
    return;
  }
  Figure b = bode("Tool-tip FRFs (" + kind + ")", curves, unit);
  b.caption = "Magnitude (log) and phase of the FRFs synthesized from the job's modal table.";
  c.figures.push_back(std::move(b));
}

void modes_table(const Outputs& o, Content& c, const std::string& file, const std::string& title) {
  const auto t = o.table(file, c, false);
  if (!t || t->rows() == 0 || t->rows() > 40)
    return;
  TextTable table{title, {}, {}};
  for (const std::string& col : t->columns())
    table.header.push_back(axis_title(col));
  for (std::size_t r = 0; r < t->rows(); ++r) {
    std::vector<std::string> row;
    for (const std::string& col : t->columns()) {
      const std::string& cell = t->text(col)[r];
      char* end = nullptr;
      const double v = std::strtod(cell.c_str(), &end);
      row.push_back(!cell.empty() && end == cell.c_str() + cell.size() ? display(v) : cell);
    }
    table.rows.push_back(std::move(row));
  }
  c.tables.push_back(std::move(table));
}

void robot(const Outputs& o, Content& c) {
  if (const auto t = o.table("frf.csv", c, false)) {
    std::vector<Curve> curves;
    const std::vector<double> f = t->numbers("freq_hz");
    for (const std::string& col : t->columns()) {
      if (!col.ends_with("_re"))
        continue;
      const std::string base = col.substr(0, col.size() - 3);
      if (!t->has(base + "_im"))
        continue;
      const auto re = t->numbers(col), im = t->numbers(base + "_im");
      Curve curve{"H" + base.substr(1), f, {}, false};
      for (std::size_t i = 0; i < re.size(); ++i)
        curve.value.emplace_back(re[i], im[i]);
      curves.push_back(std::move(curve));
    }
    if (!curves.empty()) {
      Figure b = bode("Tool-tip receptance at the posture", curves, "m/N");
      b.caption =
          "Direct (Hxx, Hyy, Hzz) and cross FRFs of the robot's joint-space model at "
          "the tool tip, tool frame.";
      c.figures.push_back(std::move(b));
    }
  }
  if (const auto t = o.table("modes.csv", c, false); t && t->has("fn_hz")) {
    Figure f = xy_figure("Mode shapes at the tool tip", "mode (natural frequency)",
                         "tip shape component (1/√kg)");
    f.caption = "Each mode's mass-normalized shape at the tool tip (tool frame).";
    f.layout["barmode"] = "group";
    json labels = json::array();
    const auto fn = t->numbers("fn_hz");
    for (std::size_t i = 0; i < fn.size(); ++i)
      labels.push_back(fmt::format("{} ({} Hz)", i + 1, display(fn[i])));
    std::size_t k = 0;
    for (const char* col : {"tip_shape_x", "tip_shape_y", "tip_shape_z"}) {
      if (!t->has(col))
        continue;
      f.data.push_back({{"type", "bar"},
                        {"name", std::string("x y z").substr(2 * k, 1)},
                        {"x", labels},
                        {"y", values(t->numbers(col))},
                        {"marker", {{"color", color(k)}}}});
      ++k;
    }
    if (!f.data.empty())
      c.figures.push_back(std::move(f));
    modes_table(o, c, "modes.csv", "Modes (modes.csv)");
  }
  if (const auto t = o.table("map.csv", c, false)) {
    const std::vector<std::string> coords = {"x_mm", "y_mm", "z_mm"};
    for (const char* value :
         {"lowest_fn_hz", "compliance_feed_um_per_N", "compliance_normal_um_per_N",
          "compliance_axial_um_per_N", "condition_number"}) {
      if (auto m = grid_map(*t, coords, value, "Workspace map: " + column_quantity(value))) {
        if (m->caption.empty())
          m->caption =
              "Over the tool-tip positions of robot.map (cell frame); blank cells are "
              "out of reach.";
        c.figures.push_back(std::move(*m));
      }
    }
  }
}

void atlas(const Outputs& o, Content& c) {
  const auto t = o.table("atlas.csv", c);
  if (!t)
    return;
  const std::vector<std::string> coords = {"x_mm", "y_mm", "z_mm", "redundancy_deg"};
  const std::set<std::string> skip = {"item", "reachable", "x_mm",
                                      "y_mm", "z_mm",      "redundancy_deg"};
  for (const std::string& col : t->columns()) {
    if (skip.count(col) || (col.size() > 5 && col[0] == 'q' && col.ends_with("_deg")))
      continue;
    if (auto m = grid_map(*t, coords, col, "Atlas: " + axis_title(col))) {
      m->caption = "Over the atlas grid (cell frame)" +
                   (m->caption.empty() ? std::string(".") : std::string(". ") + m->caption) +
                   " Blank cells are out of reach.";
      c.figures.push_back(std::move(*m));
    }
  }
  const std::vector<double> reachable = t->numbers("reachable");
  const bool some_unreachable =
      std::any_of(reachable.begin(), reachable.end(), [](double r) { return r == 0.0; });
  if (some_unreachable)
    if (auto reach = grid_map(*t, coords, "reachable", "Atlas: reachable items (1 yes, 0 no)", ""))
      c.figures.push_back(std::move(*reach));
}

void optimize(const Outputs& o, Content& c) {
  const double best_x = summary_number(o.summary, "best", "x_mm"),
               best_y = summary_number(o.summary, "best", "y_mm");
  if (const auto t = o.table("landscape.csv", c, false)) {
    for (const char* value : {"dm_mm", "max_mm"}) {
      auto m = grid_map(*t, {"x_mm", "y_mm", "theta_deg"}, value,
                        std::string("Landscape: ") + (value == std::string("dm_mm")
                                                          ? "mean tool offset dm (the objective)"
                                                          : "largest tool offset along the path"));
      if (!m)
        continue;
      m->caption = "Over the workpiece position (x, y) on the table, per inclination θ. " +
                   m->caption + " Star: the optimum.";
      if (std::isfinite(best_x)) {
        json star = marker_trace({best_x}, {best_y}, "optimum", "#ff1493", "star", 16);
        star["marker"]["line"] = {{"width", 1}, {"color", "#000"}};
        m->data.push_back(star);
        // Keep the star visible whatever the menu shows.
        if (m->layout.contains("updatemenus"))
          for (auto& button : m->layout["updatemenus"][0]["buttons"])
            button["args"][0]["visible"].push_back(true),
                button["args"][1].push_back(m->data.size() - 1);
      }
      c.figures.push_back(std::move(*m));
    }
  }
  if (const auto t = o.table("evaluations.csv", c)) {
    const std::string objective = t->has("objective_mm") ? "objective_mm" : t->columns().back();
    Figure f = xy_figure("Optimization history", "evaluation", axis_title(objective));
    f.caption =
        "Objective of every evaluated pose (global search, then local polish) and the "
        "best so far; poses out of reach are left out.";
    const auto n = t->numbers("evaluation"), phase = t->numbers("phase");
    // Unreachable poses carry a penalty value, not an offset: leave them out.
    std::vector<double> v = t->numbers(objective);
    if (t->has("reachable")) {
      const std::vector<double> reachable = t->numbers("reachable");
      for (std::size_t i = 0; i < v.size(); ++i)
        if (reachable[i] == 0.0)
          v[i] = std::nan("");
    }
    for (int p = 0; p < 2; ++p) {
      std::vector<double> x, y;
      for (std::size_t i = 0; i < n.size(); ++i)
        if ((phase.empty() ? 0 : static_cast<int>(phase[i])) == p) {
          x.push_back(n[i]);
          y.push_back(v[i]);
        }
      if (!x.empty())
        f.data.push_back(
            marker_trace(x, y, p == 0 ? "global search" : "local polish", color(p), "circle", 5));
    }
    std::vector<double> best;
    double running = std::numeric_limits<double>::infinity();
    for (double value : v) {
      if (std::isfinite(value))
        running = std::min(running, value);
      best.push_back(running);
    }
    f.data.push_back(line_trace(n, best, "best so far", 3));
    c.figures.push_back(std::move(f));
    if (t->has("x_mm") && t->has("y_mm")) {
      Figure p = xy_figure("Evaluated poses", "x (mm)", "y (mm)");
      p.caption = "Workpiece positions the search evaluated, coloured by the objective.";
      json scatter = marker_trace(t->numbers("x_mm"), t->numbers("y_mm"), "evaluations", "#1f77b4");
      scatter["marker"]["color"] = values(v);
      scatter["marker"]["colorscale"] = "Viridis";
      scatter["marker"]["colorbar"] = {{"title", {{"text", axis_title(objective)}}}};
      p.data.push_back(scatter);
      if (std::isfinite(best_x))
        p.data.push_back(marker_trace({best_x}, {best_y}, "optimum", "#ff1493", "star", 16));
      c.figures.push_back(std::move(p));
    }
  }
  if (const auto t = o.table("path.csv", c, false)) {
    const std::string value = t->has("d_mm") ? "d_mm" : "peak_mm";
    Figure f = xy_figure("Tool offset along the path", "path point", "tool offset d (mm)");
    f.caption = "Per path point, the tool offset for each reported pose (pose 0: the optimum).";
    std::size_t k = 0;
    for (const std::string& pose : t->distinct("pose")) {
      const Table part = t->where("pose", pose);
      f.data.push_back(
          line_trace(part.numbers("point"), reachable_only(part, value), "pose " + pose, k++));
      f.data.back()["mode"] = "lines+markers";
      if (k == 8)
        break;
    }
    c.figures.push_back(std::move(f));
  }
}

void advise(const Outputs& o, Content& c) {
  if (auto t = o.table("advice_map.csv", c)) {
    // Coarse and refined speeds together, in speed order.
    std::vector<double> rpm = t->numbers("spindle_rpm");
    std::vector<std::size_t> order(rpm.size());
    for (std::size_t i = 0; i < order.size(); ++i)
      order[i] = i;
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return rpm[a] < rpm[b]; });
    auto sorted = [&](const char* col) { return pick(t->numbers(col), order); };
    const std::vector<double> x = pick(rpm, order);
    Figure f;
    f.title = "Cutting-parameter advice";
    f.caption =
        "Per spindle speed: the limiting depth, the depth the advice allows (margin and "
        "tool-offset limit) and its removal rate; star: the advice.";
    stack(f, "spindle speed (rpm)", {"axial depth (mm)", "removal rate (cm³/min)"}, {2.0, 1.0});
    f.data.push_back(line_trace(x, sorted("limit_depth_mm"), "limiting depth", 0));
    if (t->has("depth_mm"))
      f.data.push_back(line_trace(x, sorted("depth_mm"), "advised depth", 2, "dash"));
    if (t->has("mrr_cm3_per_min")) {
      json mrr = line_trace(x, sorted("mrr_cm3_per_min"), "removal rate", 3);
      f.data.push_back(on_row(mrr, 1));
    }
    const double best_rpm = summary_number(o.summary, "spindle_rpm"),
                 best_depth = summary_number(o.summary, "depth_mm"),
                 best_mrr = summary_number(o.summary, "mrr_cm3_per_min");
    if (std::isfinite(best_rpm)) {
      f.data.push_back(marker_trace({best_rpm}, {best_depth}, "advice", "#ff1493", "star", 16));
      json s2 = marker_trace({best_rpm}, {best_mrr}, "advice", "#ff1493", "star", 16);
      s2["showlegend"] = false;
      f.data.push_back(on_row(s2, 1));
    }
    c.figures.push_back(std::move(f));
  }
  if (const auto t = o.table("redundancy.csv", c, false)) {
    Figure f;
    f.title = "Redundancy angle study";
    f.caption =
        "Along the path: the minimum limiting depth and the lowest natural frequency "
        "over the redundancy angle, per path point (gaps: out of reach).";
    stack(f, "redundancy angle (°)",
          {"minimum limiting depth (mm)", "lowest natural frequency (Hz)"});
    const std::vector<std::string> points = t->distinct("point");
    std::size_t k = 0;
    for (const std::string& p : points) {
      const Table part = t->where("point", p);
      f.data.push_back(line_trace(part.numbers("angle_deg"), reachable_only(part, "min_limit_mm"),
                                  "point " + p, k));
      f.data.back()["legendgroup"] = p;
      if (part.has("lowest_fn_hz")) {
        json fn = line_trace(part.numbers("angle_deg"), reachable_only(part, "lowest_fn_hz"),
                             "point " + p, k);
        fn["showlegend"] = false;
        fn["legendgroup"] = p;
        f.data.push_back(on_row(fn, 1));
      }
      if (++k == 12)
        break;
    }
    c.figures.push_back(std::move(f));
  }
}

void identify_stiffness(const Outputs& o, Content& c) {
  const auto t = o.table("fit.csv", c);
  if (!t)
    return;
  Figure parity = xy_figure("Model against measurement", "measured displacement (mm)",
                            "model displacement (mm)");
  parity.caption =
      "Each loading test's displacement, measured against the identified model's; "
      "the diagonal is perfect agreement.";
  double low = 0.0, high = 0.0;
  std::size_t k = 0;
  for (const char* a : {"x", "y", "z"}) {
    const std::string m = fmt::format("d{}_mm", a), p = fmt::format("model_d{}_mm", a);
    if (!t->has(m) || !t->has(p))
      continue;
    const auto mv = t->numbers(m), pv = t->numbers(p);
    for (double v : mv)
      if (std::isfinite(v))
        low = std::min(low, v), high = std::max(high, v);
    parity.data.push_back(marker_trace(mv, pv, std::string("d") + a, color(k++), "circle", 5));
  }
  json diagonal = trace({low, high}, {low, high}, "model = measured");
  diagonal["line"] = {{"color", "#444"}, {"dash", "dot"}};
  parity.data.push_back(diagonal);
  c.figures.push_back(std::move(parity));
  if (t->has("residual_um")) {
    Figure r = xy_figure("Residual per test", "test", "residual (µm)");
    json bars = {{"type", "bar"},
                 {"name", "residual"},
                 {"x", values(t->numbers("test"))},
                 {"y", values(t->numbers("residual_um"))},
                 {"marker", {{"color", color(0)}}}};
    r.data.push_back(bars);
    c.figures.push_back(std::move(r));
  }
}

void surface(const Outputs& o, Content& c) {
  const auto t = o.table("surface.csv", c);
  if (!t)
    return;
  const std::string value = t->has("z_um") ? "z_um" : t->columns().back();
  if (auto m = grid_map(*t, {"x_mm", "y_mm"}, value, "Surface height map")) {
    m->caption = "Machined surface height over the simulated patch.";
    c.figures.push_back(*m);
    // The same grid as a 3-D surface.
    Figure s;
    s.title = "Surface, 3-D view";
    s.caption = "Drag to rotate; heights are exaggerated by the axis scaling.";
    json surface = m->data[0];
    surface["type"] = "surface";
    surface.erase("hoverongaps");
    surface["visible"] = true;
    s.data.push_back(surface);
    s.layout["scene"] = {{"xaxis", {{"title", {{"text", "x (mm)"}}}}},
                         {"yaxis", {{"title", {{"text", "y (mm)"}}}}},
                         {"zaxis", {{"title", {{"text", axis_title(value)}}}}},
                         {"aspectmode", "manual"},
                         {"aspectratio", {{"x", 1.6}, {"y", 1}, {"z", 0.5}}}};
    s.height_px = 560;
    c.figures.push_back(std::move(s));
    // Profiles through the middle of the patch, along x and along y.
    const json& xs = m->data[0]["x"];
    const json& ys = m->data[0]["y"];
    const json& grid = m->data[0]["z"];
    if (!xs.empty() && !ys.empty()) {
      Figure p;
      p.title = "Profiles through the middle of the patch";
      stack(p, "position (mm)",
            {"height along x (" + column_unit(value) + ")",
             "height along y (" + column_unit(value) + ")"});
      const std::size_t my = ys.size() / 2, mx = xs.size() / 2;
      json along_x = {
          {"type", "scatter"}, {"mode", "lines"}, {"name", "along x"}, {"x", xs}, {"y", grid[my]}};
      json column = json::array();
      for (const auto& row : grid)
        column.push_back(row[mx]);
      json along_y = {
          {"type", "scatter"}, {"mode", "lines"}, {"name", "along y"}, {"x", ys}, {"y", column}};
      p.data.push_back(along_x);
      p.data.push_back(on_row(along_y, 1));
      c.figures.push_back(std::move(p));
    }
  }
  if (const auto v = o.table("vibration.csv", c, false)) {
    const std::vector<double> time = v->numbers("t_s");
    Figure f =
        xy_figure("Tool vibration added to the cutting edges", "time (s)", "displacement (µm)");
    f.caption =
        "Tool-tip displacement of the time-domain simulation (spindle frame, 001 Eq 26-28), "
        "from the first pass's start — or from every pass's start when the vibration restarts "
        "per pass (surface.start: rest, surface.entry).";
    std::size_t k = 0;
    for (const char* col : {"x_um", "y_um", "z_um"})
      if (v->any_nonzero(col))
        f.data.push_back(line_trace(time, v->numbers(col), std::string("u") + col[0], k++));
    if (!f.data.empty())
      c.figures.push_back(std::move(f));
  }
}

}  // namespace

void generic_figures(const std::string& file, const Table& t, Content& c) {
  if (t.rows() < 2 || t.columns().size() < 2)
    return;
  const std::string x = t.columns().front();
  Figure f = xy_figure(file, axis_title(x), "value");
  std::size_t k = 0;
  for (std::size_t i = 1; i < t.columns().size() && k < 8; ++i) {
    const std::string& col = t.columns()[i];
    if (!t.any_nonzero(col))
      continue;
    f.data.push_back(line_trace(t.numbers(x), t.numbers(col), axis_title(col), k++));
  }
  if (!f.data.empty())
    c.figures.push_back(std::move(f));
}

Content build_content(const Outputs& o) {
  Content c;
  const std::string& cmd = o.command;
  if (cmd == "forces")
    forces_figures(o, c);
  else if (cmd == "stability")
    stability(o, c);
  else if (cmd == "fit-modes") {
    fit_modes(o, c);
    modes_table(o, c, "modes.csv", "Fitted modes (modes.csv)");
  } else if (cmd == "frf")
    frf(o, c);
  else if (cmd == "robot")
    robot(o, c);
  else if (cmd == "atlas")
    atlas(o, c);
  else if (cmd == "optimize")
    optimize(o, c);
  else if (cmd == "advise")
    advise(o, c);
  else if (cmd == "simulate")
    simulate_figures(o, c);
  else if (cmd == "deflection")
    deflection_figures(o, c);
  else if (cmd == "identify-cutting")
    identify_cutting_figures(o, c);
  else if (cmd == "identify-stiffness")
    identify_stiffness(o, c);
  else if (cmd == "surface")
    surface(o, c);
  else if (cmd == "toolpath")
    toolpath_figures(o, c);
  else if (cmd == "listen")
    listen_figures(o, c);
  else if (cmd == "learn")
    learning_figures(o, c);
  else {
    for (const auto& [name, text] : o.files)
      if (name.ends_with(".csv"))
        if (const auto t = Table::parse(text))
          generic_figures(name, *t, c);
  }
  return c;
}

}  // namespace robomill::report::detail

namespace robomill::report {

bool has_dedicated_figures(std::string_view command) {
  // clang-format off
  static const std::set<std::string, std::less<>> commands = {
      "forces",   "stability",  "fit-modes",        "frf",
      "robot",    "atlas",      "optimize",         "advise",
      "simulate", "deflection", "identify-cutting", "identify-stiffness",
      "surface",  "toolpath",   "listen",           "learn"};
  // clang-format on
  return commands.count(command) > 0;
}

}  // namespace robomill::report
