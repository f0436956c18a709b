#pragma once
// Physical quantities written by people: "4 mm", "8200 rpm", "855 N/mm^2",
// "45 deg", "2.37 %", "0.6 m/min". Parsed once at the edge into SI values with
// a dimension, so a field can reject "4 rpm" where it expects a length.

#include <string>
#include <string_view>

namespace robomill::job {

/// Exponents of the base dimensions. Angle is kept as its own dimension so
/// that a spindle speed (angle/time: rpm, rad/s) is not confused with a
/// frequency (1/time: Hz).
struct Dimension {
  int length = 0, mass = 0, time = 0, angle = 0;
  friend bool operator==(const Dimension&, const Dimension&) = default;
};

namespace dimensions {
inline constexpr Dimension none{};
inline constexpr Dimension length{1, 0, 0, 0};
inline constexpr Dimension angle{0, 0, 0, 1};
inline constexpr Dimension time{0, 0, 1, 0};
inline constexpr Dimension mass{0, 1, 0, 0};
inline constexpr Dimension frequency{0, 0, -1, 0};              // Hz
inline constexpr Dimension angular_speed{0, 0, -1, 1};          // rpm, rad/s
inline constexpr Dimension speed{1, 0, -1, 0};                  // mm/min, m/s
inline constexpr Dimension force{1, 1, -2, 0};                  // N
inline constexpr Dimension pressure{-1, 1, -2, 0};              // N/mm^2, MPa, Pa
inline constexpr Dimension force_per_length{0, 1, -2, 0};       // N/mm, N/m
inline constexpr Dimension stiffness{0, 1, -2, 0};              // N/m (same as force per length)
inline constexpr Dimension force_per_volume{-2, 1, -2, 0};      // N/m^3 (indentation, 000 Eq 18)
inline constexpr Dimension torque{2, 1, -2, 0};                 // N*m
inline constexpr Dimension power{2, 1, -3, 0};                  // W (spindle power)
inline constexpr Dimension rotational_stiffness{2, 1, -2, -1};  // N*m/rad
inline constexpr Dimension moment_of_inertia{2, 1, 0, 0};       // kg*m^2
inline constexpr Dimension rotational_damping{2, 1, -1, -1};    // N*m*s/rad
inline constexpr Dimension receptance{0, -1, 2, 0};             // m/N (FRF)
inline constexpr Dimension mobility{0, -1, 1, 0};               // m/s/N (FRF)
inline constexpr Dimension accelerance{0, -1, 0, 0};            // m/s^2/N (FRF)
}  // namespace dimensions

/// Human-readable name of a dimension with its SI unit, for messages:
/// "length (m)", "pressure (N/m^2)", "angular speed (rad/s)". Combinations
/// without a name are shown by their SI unit ("kg*m^2").
std::string describe(const Dimension& dimension);

/// The name alone: "length", "angular speed", "dimensionless number"; for an
/// unnamed combination, "quantity in <SI unit>".
std::string dimension_name(const Dimension& dimension);

/// The SI unit expression of a dimension: "m", "N/m^2", "rad/s", "1" for none.
std::string si_unit(const Dimension& dimension);

/// A few units people write for a dimension, for "expected a length (mm, m,
/// um)" messages; the SI unit for a combination without a usual spelling.
std::string typical_units(const Dimension& dimension);

struct Quantity {
  double value_si = 0.0;
  Dimension dimension;
};

/// Parses "<number> [unit expression]". A unit expression is a product of
/// units with optional integer powers, separated by '*', '.', ' ' or '/':
/// "N/mm^2", "N*m/rad", "kg m^2", "m/min", "1/s". Known units: m cm mm um µm
/// nm in; kg g; s ms us min h; N kN; Pa kPa MPa GPa; Hz kHz; rad deg rev
/// rpm; % (= 0.01); tooth (dimensionless, for "mm/tooth").
/// A bare number has no dimension and value_si equal to the number; the
/// caller applies the field's documented unit. Throws std::invalid_argument
/// with a message naming the problem ("unknown unit 'mmm'").
Quantity parse_quantity(std::string_view text);

/// Parses a unit expression alone ("mm", "N/mm^2"): the SI factor of 1 unit.
/// An empty expression is the dimensionless factor 1.
Quantity parse_unit(std::string_view unit);

/// The unit expression of "<number> [unit expression]" as written, without
/// surrounding blanks ("mm/tooth" for "0.05 mm/tooth", "" for "4"). It does
/// not validate the expression; messages use it to quote what the user wrote.
std::string_view unit_part(std::string_view text);

}  // namespace robomill::job
