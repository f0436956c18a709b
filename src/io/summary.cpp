#include "robomill/io/summary.hpp"

#include <cmath>

#include "robomill/core/error.hpp"

namespace robomill::io {
namespace {

void check_finite(const nlohmann::json& node, const std::string& path) {
  if (node.is_number_float() && !std::isfinite(node.get<double>())) {
    throw NumericalError("summary value " + path + " is not finite; refusing to report it");
  }
  if (node.is_object()) {
    for (const auto& [key, child] : node.items())
      check_finite(child, path + "." + key);
  } else if (node.is_array()) {
    for (std::size_t i = 0; i < node.size(); ++i) {
      check_finite(node[i], path + "[" + std::to_string(i) + "]");
    }
  }
}

}  // namespace

nlohmann::json xyz(const Eigen::Vector3d& value) {
  return {{"x", value.x()}, {"y", value.y()}, {"z", value.z()}};
}

std::string summary_text(const nlohmann::json& summary) {
  check_finite(summary, "summary");
  return summary.dump(2) + "\n";
}

}  // namespace robomill::io
