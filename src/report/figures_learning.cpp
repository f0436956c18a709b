// The report's figures of `robomill learn` (issue 35, docs/learning.md): the
// lobes before and after the tests with every test and the next one drawn,
// the posterior chance of chatter, each variable's prior range and
// posterior samples, the posterior correlations, and the chatter
// frequencies heard against those predicted.

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "detail.hpp"
#include "figure_helpers.hpp"

namespace robomill::report::detail {
namespace {

/// The tests of experiments.csv made at `place` (green circles stable, red
/// crosses chatter) and the next test there (a star) on a figure of spindle
/// speed and depth.
void tests_overlay(const std::optional<Table>& tests, const nlohmann::json& summary, Figure& f,
                   int place = 0) {
  if (tests && tests->has("spindle_rpm") && tests->has("depth_mm") && tests->has("chatter")) {
    const std::vector<double> rpm = tests->numbers("spindle_rpm"),
                              depth = tests->numbers("depth_mm");
    const std::vector<double> chatter = tests->numbers("chatter");
    const std::vector<double> places =
        tests->has("place") ? tests->numbers("place") : std::vector<double>(rpm.size(), 0.0);
    for (int c = 0; c < 2; ++c) {
      std::vector<double> x, y;
      for (std::size_t i = 0; i < rpm.size(); ++i) {
        if ((chatter[i] > 0.5) == (c == 1) && places[i] == place) {
          x.push_back(rpm[i]);
          y.push_back(depth[i]);
        }
      }
      if (x.empty())
        continue;
      nlohmann::json t = c ? marker_trace(x, y, "test: chatter", "#d62728", "x", 11)
                           : marker_trace(x, y, "test: stable", "#2ca02c", "circle", 10);
      t["marker"]["line"] = {{"width", 1.5}, {"color", c ? "#7a0000" : "#0b5d0b"}};
      f.data.push_back(t);
    }
  }
  const nlohmann::json& next =
      summary.contains("next_test") ? summary["next_test"] : nlohmann::json();
  if (next.is_object() && next.value("found", false) && next.value("place", 0) == place) {
    nlohmann::json star = marker_trace({number_of(next, "spindle_rpm")}, {number_of(next, "ap_mm")},
                                       fmt::format("next test ({})", next.value("strategy", "")),
                                       "#ff7f0e", "star", 16);
    star["marker"]["line"] = {{"width", 1.5}, {"color", "#7a3d00"}};
    f.data.push_back(star);
  }
}

/// A band (q05 to q95, filled) and its median.
void add_band(const std::vector<double>& rpm, const std::vector<double>& q05,
              const std::vector<double>& q50, const std::vector<double>& q95,
              const std::string& label, const std::string& fill, std::size_t colour, Figure& f) {
  nlohmann::json low = line_trace(rpm, q05, label + ": 5 %", colour, "dot");
  low["legendgroup"] = label;
  f.data.push_back(low);
  nlohmann::json high = line_trace(rpm, q95, label + ": 95 %", colour, "dot");
  high["fill"] = "tonexty";
  high["fillcolor"] = fill;
  high["legendgroup"] = label;
  f.data.push_back(high);
  nlohmann::json median = line_trace(rpm, q50, label + ": median", colour, "dash");
  median["legendgroup"] = label;
  f.data.push_back(median);
}

/// The band of a lobes_quantiles table.
void add_band(const Table& q, const std::string& label, const std::string& fill, std::size_t colour,
              Figure& f) {
  add_band(q.numbers("spindle_rpm"), q.numbers("depth_limit_q05_mm"),
           q.numbers("depth_limit_q50_mm"), q.numbers("depth_limit_q95_mm"), label, fill, colour,
           f);
}

/// A robot's other places (places.csv): per place its lobes before and
/// after, with the tests made there; the posture from summary.json.
void place_figures(const Outputs& o, const std::optional<Table>& tests, Content& c) {
  const auto places = o.table("places.csv", c, false);
  if (!places || !places->has("place") || !places->has("posterior_q50_mm"))
    return;
  const std::vector<double> place = places->numbers("place");
  const int count =
      place.empty() ? 0 : static_cast<int>(*std::max_element(place.begin(), place.end())) + 1;
  for (int p = 1; p < count; ++p) {
    std::vector<std::vector<double>> column(7);
    const char* names[7] = {"spindle_rpm",     "prior_q05_mm",     "prior_q50_mm",
                            "prior_q95_mm",    "posterior_q05_mm", "posterior_q50_mm",
                            "posterior_q95_mm"};
    for (int k = 0; k < 7; ++k) {
      const std::vector<double> all = places->numbers(names[k]);
      for (std::size_t i = 0; i < all.size(); ++i)
        if (place[i] == p)
          column[static_cast<std::size_t>(k)].push_back(all[i]);
    }
    std::string posture;
    if (o.summary.contains("places") && o.summary["places"].is_array() &&
        static_cast<std::size_t>(p) < o.summary["places"].size()) {
      for (const auto& angle : o.summary["places"][static_cast<std::size_t>(p)]["posture_deg"])
        posture += fmt::format("{}{:.4g}", posture.empty() ? "" : ", ", angle.get<double>());
    }
    Figure f = xy_figure(fmt::format("Place {}: the lobes before and after", p),
                         "spindle speed (rpm)", "limiting depth (mm)");
    f.caption = fmt::format(
        "At the robot's posture [{}] deg: the limiting depth's 5-95 % band under the prior "
        "(grey) and the posterior (blue), the tests made here and the next test if it is here. "
        "The stiffness a test reveals at one posture holds at every posture.",
        posture);
    add_band(column[0], column[1], column[2], column[3], "prior", "rgba(128, 128, 128, 0.22)", 7,
             f);
    add_band(column[0], column[4], column[5], column[6], "posterior", "rgba(31, 119, 180, 0.28)", 0,
             f);
    tests_overlay(tests, o.summary, f, p);
    c.figures.push_back(std::move(f));
  }
}

/// Hammer tests (hammer_modes.csv): each fitted mode's frequency against
/// the nearest predicted mode's, under the prior and the posterior.
void hammer_figure(const Outputs& o, Content& c) {
  const auto modes = o.table("hammer_modes.csv", c, false);
  if (!modes || !modes->has("fn_hz") || !modes->has("posterior_fn_hz") || modes->rows() == 0)
    return;
  const std::vector<double> fitted = modes->numbers("fn_hz");
  Figure f =
      xy_figure("Hammer tests: fitted and predicted modes", "fitted fn (Hz)", "predicted fn (Hz)");
  f.caption =
      "Each mode fitted to a hammer test's FRF against the nearest predicted mode at that "
      "posture (the posterior median; grey: the prior's): on the line they agree.";
  const auto [low, high] = std::minmax_element(fitted.begin(), fitted.end());
  f.data.push_back(line_trace({*low, *high}, {*low, *high}, "equal", 7, "dash"));
  f.data.push_back(
      marker_trace(fitted, modes->numbers("prior_fn_hz"), "prior", "#7f7f7f", "circle-open", 9));
  f.data.push_back(
      marker_trace(fitted, modes->numbers("posterior_fn_hz"), "posterior", "#1f77b4", "x", 10));
  c.figures.push_back(std::move(f));
}

void band_figures(const Outputs& o, const std::optional<Table>& tests, Content& c) {
  const auto prior = o.table("lobes_quantiles_prior.csv", c, false);
  const auto posterior = o.table("lobes_quantiles.csv", c, false);
  const auto good = [](const std::optional<Table>& q) {
    return q && q->has("spindle_rpm") && q->has("depth_limit_q05_mm") &&
           q->has("depth_limit_q50_mm") && q->has("depth_limit_q95_mm");
  };
  if (good(prior) && good(posterior)) {
    Figure f = xy_figure("What the tests taught: the lobes before and after", "spindle speed (rpm)",
                         "limiting depth (mm)");
    f.caption =
        "The limiting depth's 5-95 % band under the prior (grey) and under the posterior "
        "(blue), each with its median (dashed), the tests learned from (green circles stable, "
        "red crosses chatter) and the next test proposed (star).";
    add_band(*prior, "prior", "rgba(128, 128, 128, 0.22)", 7, f);
    add_band(*posterior, "posterior", "rgba(31, 119, 180, 0.28)", 0, f);
    tests_overlay(tests, o.summary, f);
    c.figures.push_back(std::move(f));
  }
  if (const auto probability = o.table("chatter_probability.csv", c, false)) {
    if (auto m = grid_map(*probability, {"spindle_rpm", "depth_mm"}, "p_chatter",
                          "Probability of chatter after the tests", "")) {
      m->caption =
          "The fraction of the posterior samples whose limiting depth lies below the depth: "
          "the chance that a cut there chatters, given the tests (blue safe, red chatter), "
          "with the tests and the next one.";
      for (auto& t : m->data)
        t["zmin"] = 0.0, t["zmax"] = 1.0, t["colorscale"] = "RdBu",
        t["colorbar"]["title"]["text"] = "P(chatter)";
      tests_overlay(tests, o.summary, *m);
      c.figures.push_back(std::move(*m));
    }
  }
}

/// A histogram of the finite values as a bar trace of densities (30 bins
/// over their range): the bars drawn from numbers the report computed.
nlohmann::json density_bars(const std::vector<double>& all, const std::string& name) {
  std::vector<double> v;
  for (const double x : all)
    if (std::isfinite(x))
      v.push_back(x);
  constexpr int kBins = 30;
  std::vector<double> centres, density;
  if (!v.empty()) {
    const auto [low, high] = std::minmax_element(v.begin(), v.end());
    const double width = (*high - *low) / kBins;
    std::vector<double> counts(kBins, 0.0);
    for (const double x : v)
      counts[width > 0.0 ? std::min(kBins - 1, static_cast<int>((x - *low) / width)) : 0] += 1.0;
    for (int b = 0; b < kBins; ++b) {
      centres.push_back(*low + (b + 0.5) * width);
      density.push_back(width > 0.0 ? counts[b] / (static_cast<double>(v.size()) * width) : 0.0);
    }
  }
  nlohmann::json bars = {{"type", "bar"},
                         {"x", values(centres)},
                         {"y", values(density)},
                         {"name", name},
                         {"marker", {{"color", "rgba(31, 119, 180, 0.7)"}}}};
  bars["width"] = centres.size() > 1 ? centres[1] - centres[0] : 1.0;
  return bars;
}

/// Per variable: the posterior samples' histogram over the prior's 5-95 %
/// range (shaded) and median.
void marginal_figures(const Outputs& o, Content& c) {
  const auto samples = o.table("posterior.csv", c, false);
  const nlohmann::json& variables =
      o.summary.contains("variables") ? o.summary["variables"] : nlohmann::json();
  if (!samples || !variables.is_object())
    return;
  for (const auto& [name, v] : variables.items()) {
    if (!samples->has(name) || !v.contains("prior"))
      continue;
    const nlohmann::json& prior = v["prior"];
    const std::string unit = v.value("unit", "");
    Figure f = xy_figure(fmt::format("{}: prior and posterior", name),
                         unit == "factor" ? name + " (factor)" : fmt::format("{} ({})", name, unit),
                         "posterior density");
    f.height_px = 300;
    f.data.push_back(density_bars(samples->numbers(name), "posterior samples"));
    f.layout["shapes"] = nlohmann::json::array({{{"type", "rect"},
                                                 {"xref", "x"},
                                                 {"yref", "paper"},
                                                 {"x0", number_of(prior, "q05")},
                                                 {"x1", number_of(prior, "q95")},
                                                 {"y0", 0},
                                                 {"y1", 1},
                                                 {"fillcolor", "rgba(128, 128, 128, 0.18)"},
                                                 {"line", {{"width", 0}}}},
                                                {{"type", "line"},
                                                 {"xref", "x"},
                                                 {"yref", "paper"},
                                                 {"x0", number_of(prior, "q50")},
                                                 {"x1", number_of(prior, "q50")},
                                                 {"y0", 0},
                                                 {"y1", 1},
                                                 {"line", {{"color", "#555"}, {"dash", "dash"}}}}});
    const nlohmann::json& post = v.contains("posterior") ? v["posterior"] : nlohmann::json();
    f.caption = fmt::format(
        "Grey: the prior's 5-95 % range ({:.4g} to {:.4g}) and its median (dashed); bars: "
        "the posterior samples (5-95 %: {:.4g} to {:.4g}).",
        number_of(prior, "q05"), number_of(prior, "q95"), number_of(post, "q05"),
        number_of(post, "q95"));
    c.figures.push_back(std::move(f));
  }
}

void correlation_figure(const Outputs& o, Content& c) {
  const nlohmann::json& variables =
      o.summary.contains("variables") ? o.summary["variables"] : nlohmann::json();
  if (!variables.is_object() || variables.size() < 2)
    return;
  std::vector<std::string> names;
  for (const auto& [name, v] : variables.items())
    names.push_back(name);
  nlohmann::json z = nlohmann::json::array();
  for (const std::string& row : names) {
    nlohmann::json line = nlohmann::json::array();
    for (const std::string& column : names) {
      const nlohmann::json& r = variables[row].value("posterior_correlation", nlohmann::json());
      line.push_back(row == column ? 1.0 : r.is_object() ? number_of(r, column) : std::nan(""));
    }
    z.push_back(line);
  }
  Figure f;
  f.title = "Posterior correlations";
  f.caption =
      "Pearson correlation of the posterior samples: tests at the limit tie the variables "
      "together (a stiffer mode and a larger cutting coefficient can give the same limit).";
  f.data.push_back({{"type", "heatmap"},
                    {"x", names},
                    {"y", names},
                    {"z", z},
                    {"zmin", -1},
                    {"zmax", 1},
                    {"colorscale", "RdBu"},
                    {"reversescale", true}});
  f.layout["yaxis"] = {{"autorange", "reversed"}};
  f.height_px = 380;
  c.figures.push_back(std::move(f));
}

void chatter_frequency_figure(const std::optional<Table>& tests, Content& c) {
  if (!tests || !tests->has("chatter_freq_hz") || !tests->has("predicted_chatter_freq_hz"))
    return;
  std::vector<double> heard, predicted;
  const std::vector<double> h = tests->numbers("chatter_freq_hz");
  const std::vector<double> p = tests->numbers("predicted_chatter_freq_hz");
  for (std::size_t i = 0; i < h.size(); ++i) {
    if (h[i] > 0.0 && p[i] > 0.0) {
      heard.push_back(h[i]);
      predicted.push_back(p[i]);
    }
  }
  if (heard.empty())
    return;
  Figure f = xy_figure("Chatter frequencies: heard and predicted", "heard (Hz)",
                       "predicted, posterior median (Hz)");
  f.caption =
      "Each chattering test's chatter line against the posterior's nearest predicted family "
      "member |±fc + k·f_tooth| at that speed; the line is equality.";
  double low = heard[0], high = heard[0];
  for (std::size_t i = 0; i < heard.size(); ++i)
    low = std::min({low, heard[i], predicted[i]}), high = std::max({high, heard[i], predicted[i]});
  f.data.push_back(line_trace({low, high}, {low, high}, "equal", 7, "dash"));
  f.data.push_back(marker_trace(heard, predicted, "tests", "#d62728", "x", 11));
  c.figures.push_back(std::move(f));
}

}  // namespace

void learning_figures(const Outputs& o, Content& c) {
  const auto tests = o.table("experiments.csv", c, false);
  band_figures(o, tests, c);
  place_figures(o, tests, c);
  hammer_figure(o, c);
  marginal_figures(o, c);
  correlation_figure(o, c);
  chatter_frequency_figure(tests, c);
}

}  // namespace robomill::report::detail
