// UFF dataset 58 units: see uff58_units.hpp.

#include "uff58_units.hpp"

#include <algorithm>
#include <cctype>

#include "robomill/core/text.hpp"

namespace robomill::io::uff58_detail {
namespace {

using dynamics::FrfKind;

constexpr double kStandardGravity = 9.80665;     // m/s² per g
constexpr double kPoundForce = 4.4482216152605;  // N per lbf

}  // namespace

bool is_blank_label(std::string_view label) {
  label = text::trim(label);
  if (label.size() != 4)
    return label.empty();
  std::string upper(label);
  std::transform(upper.begin(), upper.end(), upper.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return upper == "NONE";
}

std::string normalized_label(std::string_view label) {
  std::string out;
  for (std::size_t i = 0; i < label.size(); ++i) {
    const std::string_view rest = label.substr(i);
    if (rest.starts_with("\xC2\xB2")) {  // UTF-8 superscript two
      out += "^2";
      ++i;
    } else if (rest.starts_with("\xC2\xB5") || rest.starts_with("\xCE\xBC")) {  // micro
      out += 'u';
      ++i;
    } else if (rest.starts_with("**")) {
      out += '^';
      ++i;
    } else if (label[i] != ' ' && label[i] != '(' && label[i] != ')') {
      out += label[i];
    }
  }
  return out;
}

std::optional<double> unit_in(std::string_view unit, UnitTable table) {
  for (const auto& [name, scale_to_si] : table) {
    if (unit == name)
      return scale_to_si;
  }
  return std::nullopt;
}

std::optional<double> force_unit(std::string_view unit) {
  return unit_in(
      unit, {{"N", 1.0}, {"kN", 1e3}, {"mN", 1e-3}, {"lbf", kPoundForce}, {"lb", kPoundForce}});
}

std::optional<double> length_unit(std::string_view unit) {
  return unit_in(unit, {{"m", 1.0}, {"mm", 1e-3}, {"um", 1e-6}, {"cm", 1e-2}, {"in", 0.0254}});
}

// "mm", "m/s", "m/s^2", "g", optionally over a force: "mm/N", "g/N".
std::optional<OrdinateUnit> ordinate_unit(std::string_view label) {
  std::string unit = normalized_label(label);
  OrdinateUnit result;
  if (const auto slash = unit.rfind('/'); slash != std::string::npos) {
    if (const auto force = force_unit(std::string_view(unit).substr(slash + 1))) {
      result.per_force = true;
      result.scale_to_si /= *force;
      unit.resize(slash);
    }
  }
  std::string_view body = unit;
  if (body == "g" || body == "G") {
    result.kind = FrfKind::accelerance;
    result.scale_to_si *= kStandardGravity;
    return result;
  }
  if (body.ends_with("/s^2") || body.ends_with("/s2")) {
    result.kind = FrfKind::accelerance;
    body = body.substr(0, body.rfind('/'));
  } else if (body.ends_with("/s")) {
    result.kind = FrfKind::mobility;
    body.remove_suffix(2);
  }
  const auto length = length_unit(body);
  if (!length)
    return std::nullopt;
  result.scale_to_si *= *length;
  return result;
}

std::optional<FrfKind> kind_of_specific_type(long long type) {
  if (type == 8)
    return FrfKind::receptance;
  if (type == 11)
    return FrfKind::mobility;
  if (type == 12)
    return FrfKind::accelerance;
  return std::nullopt;
}

std::optional<TimeUnit> time_unit(std::string_view label) {
  const std::string unit = normalized_label(label);
  if (const auto motion = ordinate_unit(unit); motion && !motion->per_force) {
    static constexpr const char* kSi[] = {"m", "m/s", "m/s^2"};
    return TimeUnit{kSi[static_cast<int>(motion->kind)], motion->scale_to_si};
  }
  if (const auto force = force_unit(unit))
    return TimeUnit{"N", *force};
  if (const auto pressure = unit_in(unit, {{"Pa", 1.0}, {"kPa", 1e3}, {"mPa", 1e-3}}))
    return TimeUnit{"Pa", *pressure};
  return std::nullopt;
}

Quantity quantity_of(long long type) {
  for (const Quantity& quantity : kQuantities) {
    if (quantity.type == type)
      return quantity;
  }
  return {type, "Response", ""};
}

}  // namespace robomill::io::uff58_detail
