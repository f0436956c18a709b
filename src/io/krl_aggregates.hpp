#pragma once
// The Cartesian aggregates of a KUKA KRL text rewritten in place (internal
// to src/io: the frame turns of io/krl_frame_turn.hpp and the compensation's
// moved points of io/krl_point_edits.hpp). An aggregate is found where the
// KRL reader finds it: `{…}` on one line, outside `;` comments and strings,
// numbered per line among those naming any of X, Y, Z, A, B, C (the ordinal
// of a toolpath::FrameSite).

#include <fmt/format.h>

#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace robomill::io::krl_aggregates {

/// An item "NAME value" of an aggregate's inner text: its name (upper case)
/// and where its value stands in that text.
struct Item {
  std::size_t value_begin = 0, value_end = 0;
  std::string name;
};

std::vector<Item> items_of(std::string_view inner);

/// A value as written after a component's name: a space, up to 9
/// significant digits, -0 as 0.
inline std::string krl_value(double value) {
  if (std::abs(value) < 5e-10)
    value = 0.0;
  return fmt::format(" {:.9g}", value);
}

/// One aggregate met in the text.
struct Aggregate {
  int line = 0;            ///< 1-based
  int ordinal = -1;        ///< among the line's Cartesian aggregates; -1 for others
  bool placement = false;  ///< assigned to $…, BASE_DATA[…] or TOOL_DATA[…]
  std::string_view inner;  ///< between the braces
  std::vector<Item> items;
};

/// The text with every aggregate for which `edit` returns a string given
/// that string as its inner text; everything else byte for byte.
std::string rewrite(std::string_view text,
                    const std::function<std::optional<std::string>(const Aggregate&)>& edit);

/// `inner` with the values of the named components replaced and the missing
/// ones appended (", NAME value"), in the order given.
std::string with_values(std::string_view inner, const std::vector<Item>& items,
                        const std::vector<std::pair<std::string, double>>& values);

}  // namespace robomill::io::krl_aggregates
