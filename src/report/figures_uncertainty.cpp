// The report's figures of `stability` with an uncertainty: section (issue
// 33, docs/uncertainty.md): the band the draws' limits fall in around the
// nominal lobe, and the chance of chatter over speed and depth, with the
// job's cutting tests on both.

#include <fmt/format.h>

#include <cmath>
#include <string>
#include <vector>

#include "detail.hpp"

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

}  // namespace robomill::report::detail
