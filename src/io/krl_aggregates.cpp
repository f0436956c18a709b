// The Cartesian aggregates of a KRL text rewritten in place (krl_aggregates.hpp).

#include "krl_aggregates.hpp"

#include "program_text.hpp"

#include <algorithm>
#include <cctype>

namespace robomill::io::krl_aggregates {

namespace pt = program_text;

std::vector<Item> items_of(std::string_view inner) {
  std::vector<Item> items;
  std::size_t start = 0;
  while (start <= inner.size()) {
    std::size_t end = inner.find(',', start);
    if (end == std::string_view::npos)
      end = inner.size();
    std::size_t i = start;
    while (i < end && std::isspace(static_cast<unsigned char>(inner[i])))
      ++i;
    const std::size_t name_begin = i;
    while (i < end && (std::isalnum(static_cast<unsigned char>(inner[i])) || inner[i] == '_'))
      ++i;
    if (i > name_begin)
      items.push_back({i, end, pt::to_upper(inner.substr(name_begin, i - name_begin))});
    start = end + 1;
  }
  return items;
}

std::string rewrite(std::string_view text,
                    const std::function<std::optional<std::string>(const Aggregate&)>& edit) {
  std::string out;
  out.reserve(text.size());
  int line = 1;
  int ordinal = 0;                  // Cartesian aggregates before, on this line
  std::size_t statement_start = 0;  // in `text`: the start of the current line
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      ordinal = 0;
      statement_start = i + 1;
      out += c;
      continue;
    }
    if (c == ';') {  // a comment (;FOLD … %{PE}) runs to the end of the line
      const std::size_t end = text.find('\n', i);
      const std::size_t stop = end == std::string_view::npos ? text.size() : end;
      out.append(text.substr(i, stop - i));
      i = stop - 1;
      continue;
    }
    if (c == '"') {  // a string
      const std::size_t end = text.find('"', i + 1);
      const std::size_t stop = end == std::string_view::npos ? text.size() : end + 1;
      out.append(text.substr(i, stop - i));
      i = stop - 1;
      continue;
    }
    const std::size_t close = c == '{' ? text.find_first_of("}\n", i + 1) : std::string_view::npos;
    if (close == std::string_view::npos || text[close] != '}') {
      out += c;
      continue;
    }
    Aggregate a;
    a.line = line;
    a.inner = text.substr(i + 1, close - i - 1);
    a.items = items_of(a.inner);
    const std::string target =
        pt::to_upper(pt::trim(text.substr(statement_start, i - statement_start)));
    // A system variable ($BASE, $TOOL, …) or the base and tool tables place
    // frames, not the tool's path.
    a.placement = !target.empty() && (target.front() == '$' || target.rfind("BASE_DATA", 0) == 0 ||
                                      target.rfind("TOOL_DATA", 0) == 0);
    const bool cartesian = std::any_of(a.items.begin(), a.items.end(), [](const Item& item) {
      return item.name.size() == 1 &&
             std::string_view("XYZABC").find(item.name[0]) != std::string_view::npos;
    });
    a.ordinal = cartesian ? ordinal++ : -1;
    const std::optional<std::string> replaced = edit(a);
    out += '{';
    out += replaced ? *replaced : std::string(a.inner);
    out += '}';
    i = close;
  }
  return out;
}

std::string with_values(std::string_view inner, const std::vector<Item>& items,
                        const std::vector<std::pair<std::string, double>>& values) {
  std::string out(inner);
  // Replaced from the last value in the text back, so spans stay valid.
  std::vector<std::pair<const Item*, double>> present;
  std::string appended;
  for (const std::pair<std::string, double>& named : values) {
    const auto it = std::find_if(items.begin(), items.end(),
                                 [&](const Item& item) { return item.name == named.first; });
    if (it != items.end())
      present.emplace_back(&*it, named.second);
    else
      appended += "," + named.first + krl_value(named.second);
  }
  std::sort(present.begin(), present.end(), [](const auto& a, const auto& b) {
    return a.first->value_begin > b.first->value_begin;
  });
  for (const auto& [item, value] : present)
    out.replace(item->value_begin, item->value_end - item->value_begin, krl_value(value));
  return out + appended;
}

}  // namespace robomill::io::krl_aggregates
