#include "robomill/job/units.hpp"

#include "robomill/core/constants.hpp"
#include "robomill/core/text.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <stdexcept>
#include <string>
#include <system_error>

namespace robomill::job {
namespace {

struct UnitDefinition {
  std::string_view name;
  double factor;  // SI value of one unit
  Dimension dimension;
};

// The units a job may use. Prefixed forms are listed explicitly rather than
// composed from SI prefixes so that "mN" or "Mm" (almost always typos in a
// milling job) are rejected instead of silently accepted.
constexpr std::array kUnits = {
    UnitDefinition{"m", 1.0, dimensions::length},
    UnitDefinition{"cm", 1e-2, dimensions::length},
    UnitDefinition{"mm", 1e-3, dimensions::length},
    UnitDefinition{"um", 1e-6, dimensions::length},
    UnitDefinition{"\u00b5m", 1e-6, dimensions::length},  // micro sign
    UnitDefinition{"\u03bcm", 1e-6, dimensions::length},  // Greek small mu
    UnitDefinition{"nm", 1e-9, dimensions::length},
    UnitDefinition{"in", 0.0254, dimensions::length},
    UnitDefinition{"kg", 1.0, dimensions::mass},
    UnitDefinition{"g", 1e-3, dimensions::mass},
    UnitDefinition{"s", 1.0, dimensions::time},
    UnitDefinition{"ms", 1e-3, dimensions::time},
    UnitDefinition{"us", 1e-6, dimensions::time},
    UnitDefinition{"\u00b5s", 1e-6, dimensions::time},
    UnitDefinition{"\u03bcs", 1e-6, dimensions::time},
    UnitDefinition{"min", 60.0, dimensions::time},
    UnitDefinition{"h", 3600.0, dimensions::time},
    UnitDefinition{"N", 1.0, dimensions::force},
    UnitDefinition{"kN", 1e3, dimensions::force},
    UnitDefinition{"Pa", 1.0, dimensions::pressure},
    UnitDefinition{"kPa", 1e3, dimensions::pressure},
    UnitDefinition{"MPa", 1e6, dimensions::pressure},
    UnitDefinition{"GPa", 1e9, dimensions::pressure},
    UnitDefinition{"W", 1.0, dimensions::power},
    UnitDefinition{"kW", 1e3, dimensions::power},
    UnitDefinition{"Hz", 1.0, dimensions::frequency},
    UnitDefinition{"kHz", 1e3, dimensions::frequency},
    UnitDefinition{"rad", 1.0, dimensions::angle},
    UnitDefinition{"deg", kPi / 180.0, dimensions::angle},
    UnitDefinition{"rev", 2.0 * kPi, dimensions::angle},
    UnitDefinition{"rpm", 2.0 * kPi / 60.0, dimensions::angular_speed},
    UnitDefinition{"%", 0.01, dimensions::none},
    UnitDefinition{"tooth", 1.0, dimensions::none},
};

constexpr std::string_view kKnownUnitList =
    "m, cm, mm, um, nm, in, kg, g, s, ms, us, min, h, N, kN, Pa, kPa, MPa, GPa, Hz, kHz, rad, "
    "deg, rev, rpm, %, tooth";

struct NamedDimension {
  Dimension dimension;
  std::string_view name;
  std::string_view si;
  std::string_view typical;
};

// Stiffness and force per length share a dimension; the first entry names it.
constexpr std::array kNamedDimensions = {
    NamedDimension{dimensions::none, "dimensionless number", "1", "a plain number or %"},
    NamedDimension{dimensions::length, "length", "m", "mm, m, um"},
    NamedDimension{dimensions::angle, "angle", "rad", "deg, rad"},
    NamedDimension{dimensions::time, "time", "s", "s, ms, min"},
    NamedDimension{dimensions::mass, "mass", "kg", "kg, g"},
    NamedDimension{dimensions::frequency, "frequency", "Hz", "Hz, kHz"},
    NamedDimension{dimensions::angular_speed, "angular speed", "rad/s", "rpm, rad/s"},
    NamedDimension{dimensions::speed, "speed", "m/s", "mm/min, m/min, m/s"},
    NamedDimension{dimensions::force, "force", "N", "N, kN"},
    NamedDimension{dimensions::pressure, "pressure", "N/m^2", "N/mm^2, MPa, Pa"},
    NamedDimension{dimensions::force_per_length, "force per length", "N/m", "N/mm, N/m"},
    NamedDimension{dimensions::force_per_volume, "force per volume", "N/m^3", "N/mm^3, N/m^3"},
    NamedDimension{dimensions::torque, "torque", "N*m", "N*m"},
    NamedDimension{dimensions::power, "power", "W", "W, kW"},
    NamedDimension{dimensions::rotational_stiffness, "rotational stiffness", "N*m/rad", "N*m/rad"},
    NamedDimension{dimensions::moment_of_inertia, "moment of inertia", "kg*m^2", "kg*m^2"},
    NamedDimension{dimensions::rotational_damping, "rotational damping", "N*m*s/rad", "N*m*s/rad"},
    NamedDimension{dimensions::receptance, "receptance", "m/N", "m/N, mm/N, um/N"},
    NamedDimension{dimensions::mobility, "mobility", "m/s/N", "m/s/N, mm/s/N"},
    NamedDimension{dimensions::accelerance, "accelerance", "m/s^2/N", "m/s^2/N"},
};

const NamedDimension* find_named(const Dimension& dimension) {
  for (const auto& named : kNamedDimensions) {
    if (named.dimension == dimension)
      return &named;
  }
  return nullptr;
}

bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n';
}
using text::is_digit;
using text::trim;

// Length of the leading decimal number ([+-]digits[.digits][e[+-]digits]),
// 0 when the text does not start with one. Written by hand instead of relying
// on from_chars' grammar so that "inf", "nan" and hexadecimal never count as
// numbers and an incomplete exponent ("4e") is left to the unit.
std::size_t number_length(std::string_view text) {
  std::size_t i = 0;
  if (i < text.size() && (text[i] == '+' || text[i] == '-'))
    ++i;
  std::size_t digits = 0;
  while (i < text.size() && is_digit(text[i]))
    ++i, ++digits;
  if (i < text.size() && text[i] == '.') {
    // "4.mm" reads as 4 mm, but ".": a lone dot is no number.
    std::size_t j = i + 1;
    std::size_t fraction = 0;
    while (j < text.size() && is_digit(text[j]))
      ++j, ++fraction;
    if (digits + fraction > 0)
      i = j, digits += fraction;
  }
  if (digits == 0)
    return 0;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    std::size_t j = i + 1;
    if (j < text.size() && (text[j] == '+' || text[j] == '-'))
      ++j;
    std::size_t exponent_digits = 0;
    while (j < text.size() && is_digit(text[j]))
      ++j, ++exponent_digits;
    if (exponent_digits > 0)
      i = j;
  }
  return i;
}

bool looks_non_finite(std::string_view text) {
  if (!text.empty() && (text.front() == '+' || text.front() == '-'))
    text.remove_prefix(1);
  if (!text.empty() && text.front() == '.')
    text.remove_prefix(1);
  if (text.size() < 3)
    return false;
  auto lower = [](char c) { return static_cast<char>(c >= 'A' && c <= 'Z' ? c + 32 : c); };
  const std::string head{lower(text[0]), lower(text[1]), lower(text[2])};
  return head == "inf" || head == "nan";
}

std::string quoted(std::string_view text) {
  return "'" + std::string(text) + "'";
}

Dimension scaled(const Dimension& d, int power) {
  return {d.length * power, d.mass * power, d.time * power, d.angle * power};
}

Dimension plus(const Dimension& a, const Dimension& b) {
  return {a.length + b.length, a.mass + b.mass, a.time + b.time, a.angle + b.angle};
}

// Separators between factors. The middle dot (U+00B7, "N·m") is two bytes.
bool is_separator_at(std::string_view text, std::size_t i, std::size_t* width) {
  const char c = text[i];
  if (c == '*' || c == '.' || c == '/' || is_blank(c)) {
    *width = 1;
    return true;
  }
  if (c == '\xc2' && i + 1 < text.size() && text[i + 1] == '\xb7') {
    *width = 2;
    return true;
  }
  return false;
}

// Unicode superscripts "²" and "³" at the end of a unit name ("mm²").
int trailing_superscript(std::string_view* token) {
  if (token->size() >= 2 && (*token)[token->size() - 2] == '\xc2') {
    const char last = token->back();
    const int power = last == '\xb2' ? 2 : last == '\xb3' ? 3 : last == '\xb9' ? 1 : 0;
    if (power != 0)
      token->remove_suffix(2);
    return power;
  }
  return 0;
}

struct UnitValue {
  long double factor = 1.0L;
  Dimension dimension;
};

// Parses a unit expression. `allow_leading_slash` accepts "/s" after a number
// ("5/s"). Everything after the first '/' is in the denominator.
UnitValue parse_unit_expression(std::string_view expression, bool allow_leading_slash) {
  const std::string_view original = expression;
  auto malformed = [&](const std::string& why) {
    return std::invalid_argument("invalid unit " + quoted(trim(original)) + ": " + why);
  };
  UnitValue result;
  bool denominator = false;
  bool expect_factor = true;  // at the start, or right after a separator
  bool any_factor = false;
  std::size_t i = 0;
  const std::string_view text = expression;
  while (i < text.size()) {
    std::size_t width = 0;
    if (is_separator_at(text, i, &width)) {
      // A run of blanks with at most one explicit separator (' * ', '/').
      int explicit_separators = 0;
      bool slash = false;
      while (i < text.size() && is_separator_at(text, i, &width)) {
        if (!is_blank(text[i])) {
          ++explicit_separators;
          slash = slash || text[i] == '/';
        }
        i += width;
      }
      if (explicit_separators > 1)
        throw malformed("two separators in a row");
      if (!any_factor && explicit_separators == 1 && !(slash && allow_leading_slash)) {
        throw malformed("starts with a separator");
      }
      if (slash)
        denominator = true;
      expect_factor = true;
      if (i == text.size()) {
        if (explicit_separators == 1)
          throw malformed("ends with a separator");
        break;
      }
      continue;
    }
    if (!expect_factor)
      throw malformed("missing separator");
    const std::size_t start = i;
    while (i < text.size() && text[i] != '^' && !is_separator_at(text, i, &width))
      ++i;
    std::string_view token = text.substr(start, i - start);
    if (token.empty())
      throw malformed("'^' without a unit");
    int power = trailing_superscript(&token);
    if (power == 0)
      power = 1;
    if (i < text.size() && text[i] == '^') {
      ++i;
      bool negative = false;
      if (i < text.size() && (text[i] == '-' || text[i] == '+'))
        negative = text[i++] == '-';
      const std::size_t digits_start = i;
      while (i < text.size() && is_digit(text[i]))
        ++i;
      const std::string_view digits = text.substr(digits_start, i - digits_start);
      if (digits.empty())
        throw malformed("expected an integer power after '^'");
      // Powers beyond 9 are never meaningful for a physical quantity and would
      // only risk overflowing the exponent arithmetic.
      if (digits.size() > 1)
        throw malformed("power " + std::string(digits) + " is too large");
      power = (negative ? -1 : 1) * (digits[0] - '0');
    }
    if (denominator)
      power = -power;

    if (token == "1") {
      // "1/s": the numerator placeholder; dimensionless and without scale.
    } else {
      const UnitDefinition* unit = nullptr;
      for (const auto& candidate : kUnits) {
        if (candidate.name == token)
          unit = &candidate;
      }
      if (unit == nullptr) {
        throw std::invalid_argument("unknown unit " + quoted(token) + " in " +
                                    quoted(trim(original)) +
                                    "; known units: " + std::string(kKnownUnitList));
      }
      const long double factor = unit->factor;
      for (int k = 0; k < std::abs(power); ++k) {
        result.factor = power > 0 ? result.factor * factor : result.factor / factor;
      }
      result.dimension = plus(result.dimension, scaled(unit->dimension, power));
    }
    any_factor = true;
    expect_factor = false;
  }
  return result;
}

std::string unnamed_si_unit(const Dimension& d) {
  // Base units in a conventional order; negative powers go after a '/'.
  const std::array<std::pair<std::string_view, int>, 4> parts = {
      {{"kg", d.mass}, {"m", d.length}, {"rad", d.angle}, {"s", d.time}}};
  std::string numerator, denominator;
  for (const auto& [name, power] : parts) {
    if (power == 0)
      continue;
    std::string& side = power > 0 ? numerator : denominator;
    if (!side.empty())
      side += "*";
    side += name;
    if (std::abs(power) != 1) {
      side += '^';
      side += std::to_string(std::abs(power));
    }
  }
  if (numerator.empty())
    numerator.push_back('1');  // push_back: GCC 12 warns falsely (-Wrestrict) on = "1"
  if (!denominator.empty()) {
    numerator += '/';
    numerator += denominator;
  }
  return numerator;
}

}  // namespace

std::string si_unit(const Dimension& dimension) {
  if (const NamedDimension* named = find_named(dimension))
    return std::string(named->si);
  return unnamed_si_unit(dimension);
}

std::string dimension_name(const Dimension& dimension) {
  if (const NamedDimension* named = find_named(dimension))
    return std::string(named->name);
  return "quantity in " + unnamed_si_unit(dimension);
}

std::string describe(const Dimension& dimension) {
  if (const NamedDimension* named = find_named(dimension)) {
    return std::string(named->name) + " (" + std::string(named->si) + ")";
  }
  return unnamed_si_unit(dimension);
}

std::string typical_units(const Dimension& dimension) {
  if (const NamedDimension* named = find_named(dimension))
    return std::string(named->typical);
  return unnamed_si_unit(dimension);
}

std::string_view unit_part(std::string_view text) {
  text = trim(text);
  return trim(text.substr(number_length(text)));
}

Quantity parse_unit(std::string_view unit) {
  const UnitValue value = parse_unit_expression(trim(unit), false);
  return {static_cast<double>(value.factor), value.dimension};
}

Quantity parse_quantity(std::string_view text) {
  const std::string_view trimmed = trim(text);
  if (trimmed.empty())
    throw std::invalid_argument("empty value; expected a number");
  const std::size_t length = number_length(trimmed);
  if (length == 0) {
    if (looks_non_finite(trimmed)) {
      throw std::invalid_argument(quoted(trimmed) + " is not a finite number");
    }
    throw std::invalid_argument("expected a number, got " + quoted(trimmed));
  }
  std::string_view number = trimmed.substr(0, length);
  if (number.front() == '+')
    number.remove_prefix(1);  // from_chars rejects '+'
  double value = 0.0;
  const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), value);
  if (error == std::errc::result_out_of_range) {
    throw std::invalid_argument("number " + quoted(number) + " is out of range");
  }
  if (error != std::errc() || end != number.data() + number.size()) {
    throw std::invalid_argument("expected a number, got " + quoted(trimmed));
  }
  const std::string_view unit = trimmed.substr(length);
  const UnitValue factor = parse_unit_expression(unit, true);
  const long double si = static_cast<long double>(value) * factor.factor;
  const double result = static_cast<double>(si);
  if (!std::isfinite(result) || (result == 0.0 && si != 0.0L)) {
    throw std::invalid_argument(quoted(trimmed) + " is out of range");
  }
  return {result, factor.dimension};
}

}  // namespace robomill::job
