#pragma once
// Private to the figures of report.html: the helpers more than one
// src/report/figures*.cpp draws with (one definition each).

#include <fmt/format.h>

#include <cmath>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

#include "detail.hpp"

namespace robomill::report::detail {

inline constexpr std::size_t kTimePoints = 5000;  // per time trace, extremes kept (4 a pixel)
inline constexpr const char* kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd",
                                          "#ff7f0e", "#17becf", "#8c564b", "#e377c2"};

/// The 3-D views look from the front right, above, a little further out
/// than Plotly's default (which clips the y axis of a long part).
inline nlohmann::json camera() {
  return {{"eye", {{"x", 1.45}, {"y", -1.65}, {"z", 1.1}}}};
}

/// A number of `object` (NaN when it is not an object, lacks `key` or holds
/// no number there).
inline double number_of(const nlohmann::json& object, const std::string& key) {
  if (!object.is_object())
    return std::nan("");
  const auto it = object.find(key);
  return it != object.end() && it->is_number() ? it->get<double>() : std::nan("");
}

inline std::string integer_text(double value) {
  return std::isfinite(value) ? fmt::format("{}", std::llround(value)) : "—";
}

/// A summary value for a table: integers as such, numbers to 4 digits.
inline std::string json_text(const nlohmann::json& value) {
  if (value.is_string())
    return value.get<std::string>();
  if (value.is_number_integer() || value.is_number_unsigned())
    return value.dump();
  if (value.is_number())
    return display(value.get<double>());
  return value.is_null() ? "—" : value.dump();
}

}  // namespace robomill::report::detail
