#include <cstddef>
#include <string_view>

#include "robomill/report/report.hpp"

// Defined by the generated plotly_js.cpp (cmake/plotly.cmake): plotly.min.js
// through the assembler's .incbin, followed by a NUL.
extern "C" const char robomill_plotly_js_begin[];
extern "C" const char robomill_plotly_js_end[];

namespace robomill::report {

std::string_view plotly_js() noexcept {
  return {robomill_plotly_js_begin,
          static_cast<std::size_t>(robomill_plotly_js_end - robomill_plotly_js_begin)};
}

}  // namespace robomill::report
