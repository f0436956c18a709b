#pragma once
// Private to the commands: JSON helpers more than one command writes with.

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace robomill::commands::detail {

/// `v` as a JSON array, each value times `scale`.
inline nlohmann::json vector_json(const Eigen::VectorXd& v, double scale = 1.0) {
  nlohmann::json values = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i)
    values.push_back(v[i] * scale);
  return values;
}

}  // namespace robomill::commands::detail
