// UFF dataset 58 units (internal to src/io): the unit labels of records
// 8-11 and the quantities of record 9's specific data types, read by
// uff58.cpp and written by uff58_writer.cpp.
#pragma once

#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "robomill/dynamics/frf.hpp"

namespace robomill::io::uff58_detail {

/// Whether a units label is blank ("" or "NONE", any case).
bool is_blank_label(std::string_view label);

/// A label without blanks and parentheses, ² and ** as ^, µ as u.
std::string normalized_label(std::string_view label);

using UnitTable = std::initializer_list<std::pair<std::string_view, double>>;

std::optional<double> unit_in(std::string_view unit, UnitTable table);
std::optional<double> force_unit(std::string_view unit);
std::optional<double> length_unit(std::string_view unit);

struct OrdinateUnit {
  double scale_to_si = 1.0;
  dynamics::FrfKind kind = dynamics::FrfKind::receptance;
  bool per_force = false;  ///< the label already divides by a force ("mm/N")
};

// "mm", "m/s", "m/s^2", "g", optionally over a force: "mm/N", "g/N".
std::optional<OrdinateUnit> ordinate_unit(std::string_view label);

std::optional<dynamics::FrfKind> kind_of_specific_type(long long type);

// A time record's ordinate unit: the SI unit it converts to and the factor;
// nullopt for a label that names no unit known here (volts, counts).
struct TimeUnit {
  std::string si;
  double scale_to_si = 1.0;
};

std::optional<TimeUnit> time_unit(std::string_view label);

// Record 9 specific data types of time records: the quantity's name and the
// SI unit it implies when the label is blank.
struct Quantity {
  long long type;
  const char* name;
  const char* si_unit;
};
inline constexpr Quantity kQuantities[] = {
    {8, "Displacement", "m"}, {11, "Velocity", "m/s"}, {12, "Acceleration", "m/s^2"},
    {9, "Force", "N"},        {13, "Force", "N"},      {15, "Pressure", "Pa"}};

Quantity quantity_of(long long type);

}  // namespace robomill::io::uff58_detail
