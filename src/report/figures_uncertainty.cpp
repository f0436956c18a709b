// The report's figures of `stability` with an uncertainty: section (issue
// 33, docs/uncertainty.md): the band the draws' limits fall in around the
// nominal lobe, and the chance of chatter over speed and depth, with the
// job's cutting tests on both.

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "detail.hpp"
#include "figure_helpers.hpp"

namespace robomill::report::detail {

void stability_band_figures(const Outputs& o, Content& c) {
  const auto quantiles = o.table("lobes_quantiles.csv", c, false);
  const auto probability = o.table("chatter_probability.csv", c, false);
  const nlohmann::json& u =
      o.summary.contains("uncertainty") ? o.summary["uncertainty"] : nlohmann::json::object();
  const std::string draws =
      u.contains("draws") ? fmt::format("{} draws", u["draws"].dump()) : std::string("the draws");
  if (quantiles && quantiles->has("spindle_rpm") && quantiles->has("depth_limit_q05_mm") &&
      quantiles->has("depth_limit_q95_mm")) {
    Figure f = xy_figure("Stability lobes with their uncertainty", "spindle speed (rpm)",
                         "limiting depth (mm)");
    f.caption = fmt::format(
        "The limiting depth of the nominal inputs (line) and of {} of the uncertain inputs: "
        "90 % of them lie in the shaded band (5 % and 95 % quantiles), the dashed line is their "
        "median. A cut below the band's lower edge chatters in fewer than 5 % of the draws.",
        draws);
    const std::vector<double> rpm = quantiles->numbers("spindle_rpm");
    nlohmann::json low =
        line_trace(rpm, quantiles->numbers("depth_limit_q05_mm"), "5 % quantile", 0, "dot");
    low["legendgroup"] = "band";
    f.data.push_back(low);
    nlohmann::json high =
        line_trace(rpm, quantiles->numbers("depth_limit_q95_mm"), "95 % quantile", 0, "dot");
    high["fill"] = "tonexty";
    high["fillcolor"] = "rgba(31, 119, 180, 0.18)";
    high["legendgroup"] = "band";
    f.data.push_back(high);
    if (quantiles->has("depth_limit_q50_mm"))
      f.data.push_back(line_trace(rpm, quantiles->numbers("depth_limit_q50_mm"),
                                  "median of the draws", 1, "dash"));
    if (quantiles->has("depth_limit_nominal_mm"))
      f.data.push_back(
          line_trace(rpm, quantiles->numbers("depth_limit_nominal_mm"), "nominal inputs", 3));
    if (u.contains("robust_pockets") && u["robust_pockets"].is_array()) {
      std::vector<double> x, y;
      for (const nlohmann::json& pocket : u["robust_pockets"]) {
        x.push_back(pocket.value("spindle_rpm", std::nan("")));
        y.push_back(pocket.value("depth_limit_q05_mm", std::nan("")));
      }
      if (!x.empty()) {
        f.data.push_back(marker_trace(x, y, "robust pockets (highest 5 % quantile)", "#2c7fb8",
                                      "triangle-up", 11));
        f.caption += " Triangles: the robust pockets, the speeds whose 5 % quantile is highest.";
      }
    }
    experiments_overlay(o, f);
    c.figures.push_back(std::move(f));
  }
  if (probability) {
    if (auto m = grid_map(*probability, {"spindle_rpm", "depth_mm"}, "p_chatter",
                          "Probability of chatter", "")) {
      m->caption = fmt::format(
          "The fraction of {} whose limiting depth lies below the depth: the chance that a "
          "cut at that speed and depth chatters, given the uncertain inputs (its Monte-Carlo "
          "standard error is chatter_probability.csv's p_chatter_se). Blue: safe; red: "
          "chatter. The line is the nominal lobe.",
          draws);
      for (auto& t : m->data)
        t["zmin"] = 0.0, t["zmax"] = 1.0, t["colorscale"] = "RdBu",
        t["colorbar"]["title"]["text"] = "P(chatter)";
      if (quantiles && quantiles->has("depth_limit_nominal_mm")) {
        nlohmann::json line =
            line_trace(quantiles->numbers("spindle_rpm"),
                       quantiles->numbers("depth_limit_nominal_mm"), "nominal lobe", 0);
        line["line"]["color"] = "#000";
        m->data.push_back(line);
      }
      experiments_overlay(o, *m);
      c.figures.push_back(std::move(*m));
    }
  }
}

void path_uncertainty_figures(const Table* s, const nlohmann::json& along, Content& c) {
  const auto it = along.find("uncertainty");
  if (it == along.end() || !it->is_object())
    return;
  const nlohmann::json& u = *it;
  const double bound = number_of(u, "max_chatter_probability");
  const std::string draws = fmt::format("{} draws", integer_text(number_of(u, "draws")));
  if (s != nullptr && s->has("t_s") && s->has("p_chatter") && s->has("ap_limit_q05_mm") &&
      s->has("ap_limit_q95_mm") && s->has("ap_limit_mm") && s->has("ap_mm")) {
    const std::vector<double> t = s->numbers("t_s"), line = s->numbers("line");
    const std::vector<double> p = s->numbers("p_chatter");
    // Only the samples with draws (in the cut, reachable): the rest are gaps.
    std::vector<double> ap = s->numbers("ap_mm");
    for (std::size_t i = 0; i < ap.size(); ++i)
      if (i >= p.size() || !std::isfinite(p[i]))
        ap[i] = std::nan("");
    Figure f;
    f.title = "Chatter probability along the program";
    stack(f, axis_title("t_s"), {"axial depth (mm)", "P(chatter)"}, {1.2, 1.0});
    f.height_px = 640;
    f.layout["hovermode"] = "x unified";
    f.layout["legend"] = {{"orientation", "h"}, {"y", -0.12}};
    const std::vector<std::size_t> at = thin(t.size(), kTimePoints);
    auto series = [&](const std::string& column, const std::string& name, const char* colour,
                      const std::string& dash) {
      nlohmann::json tr = trace(pick(t, at), pick(s->numbers(column), at), name);
      tr["line"] = {{"color", colour}, {"width", 1.2}, {"dash", dash}};
      tr["customdata"] = integers(pick(line, at));
      tr["hovertemplate"] = name + " %{y:.4g} (line %{customdata})<extra></extra>";
      return tr;
    };
    nlohmann::json low = series("ap_limit_q05_mm", "5 % quantile of the limit", "#1f77b4", "dot");
    low["legendgroup"] = "band";
    f.data.push_back(on_row(low, 0));
    nlohmann::json high = series("ap_limit_q95_mm", "95 % quantile of the limit", "#1f77b4", "dot");
    high["fill"] = "tonexty";
    high["fillcolor"] = "rgba(31, 119, 180, 0.18)";
    high["legendgroup"] = "band";
    f.data.push_back(on_row(high, 0));
    nlohmann::json nominal = series("ap_limit_mm", "nominal limit", "#2c3e50", "solid");
    f.data.push_back(on_row(nominal, 0));
    nlohmann::json cut = trace(pick(t, at), pick(ap, at), "depth cut");
    cut["line"] = {{"color", "#d62728"}, {"width", 1.6}};
    f.data.push_back(on_row(cut, 0));
    nlohmann::json probability = series("p_chatter", "P(chatter)", "#d62728", "solid");
    if (s->has("p_chatter_se")) {
      probability["error_y"] = {
          {"type", "data"},  {"array", values(pick(s->numbers("p_chatter_se"), at))},
          {"visible", true}, {"thickness", 0.6},
          {"width", 0},      {"color", "rgba(214, 39, 40, 0.4)"}};
    }
    f.data.push_back(on_row(probability, 1));
    if (std::isfinite(bound))
      f.layout["shapes"] = nlohmann::json::array(
          {{{"type", "line"},
            {"xref", "paper"},
            {"yref", "y2"},
            {"x0", 0},
            {"x1", 1},
            {"y0", bound},
            {"y1", bound},
            {"line", {{"color", "#d62728"}, {"dash", "dash"}, {"width", 1}}}}});
    f.layout["yaxis2"]["range"] = {0, 1};
    f.caption = fmt::format(
        "Top: the axial depth each sample cuts (red), its nominal stable depth (line) and the band "
        "90 % of {} of the uncertain inputs put it in (5 % to 95 % quantiles, shaded), at the "
        "sample's own posture, engagement and spindle speed. Bottom: P(chatter), the fraction "
        "of the draws whose stable depth lies at or below the depth cut, with its Monte-Carlo "
        "standard error as bars; the dashed line is robot_path.max_chatter_probability ({}). "
        "Where the red depth enters the band the verdict is uncertain; hover shows each sample's "
        "program line. samples_preview.csv, evenly thinned.",
        draws, std::isfinite(bound) ? display(100.0 * bound) + " %" : std::string("—"));
    c.figures.push_back(std::move(f));
  }
  TextTable table;
  table.title = fmt::format(
      "Program lines whose P(chatter) over {} exceeds {} (summary.json "
      "robot_along_path.uncertainty.lines_over_bound)",
      draws, std::isfinite(bound) ? display(100.0 * bound) + " %" : std::string("the bound"));
  table.header = {"line",
                  axis_title("t_s"),
                  "P(chatter)",
                  "± se",
                  axis_title("ap_mm"),
                  "nominal stable ap (mm)",
                  "5 % quantile of stable ap (mm)"};
  if (const auto lines = u.find("lines_over_bound"); lines != u.end() && lines->is_array())
    for (const nlohmann::json& l : *lines)
      table.rows.push_back({integer_text(number_of(l, "line")), display(number_of(l, "t_s")),
                            display(number_of(l, "p_chatter")),
                            display(number_of(l, "p_chatter_se")), display(number_of(l, "ap_mm")),
                            display(number_of(l, "ap_limit_mm")),
                            display(number_of(l, "ap_limit_q05_mm"))});
  const double listed = static_cast<double>(table.rows.size());
  if (const double count = number_of(u, "lines_over_bound_count"); count > listed)
    table.title += fmt::format("; the first {} of {}", integer_text(listed), integer_text(count));
  if (table.rows.empty())
    table.rows.push_back({"none", "—", "—", "—", "—", "—", "—"});
  c.tables.push_back(std::move(table));
  // The expectations beside the nominal count.
  TextTable totals;
  totals.title = "Chatter over the draws (summary.json robot_along_path.uncertainty)";
  totals.header = {"result", "value", "line"};
  totals.rows.push_back({"draws", integer_text(number_of(u, "draws")), ""});
  totals.rows.push_back({"expected chattering samples",
                         fmt::format("{} ± {}", display(number_of(u, "expected_chatter_samples")),
                                     display(number_of(u, "expected_chatter_samples_se"))),
                         ""});
  totals.rows.push_back({"chattering samples, nominal inputs",
                         integer_text(number_of(along, "chatter_samples")), ""});
  totals.rows.push_back({"highest P(chatter)",
                         fmt::format("{} ± {}", display(number_of(u, "max_p_chatter")),
                                     display(number_of(u, "max_p_chatter_se"))),
                         integer_text(number_of(u, "max_p_chatter_line"))});
  c.tables.push_back(std::move(totals));
}

}  // namespace robomill::report::detail
