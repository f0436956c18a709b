#pragma once
// summary.json: the key figures of a command, machine-readable. Scripts read
// these keys (DESIGN.md §3), so a key once released keeps its name.

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>

namespace robomill::io {

/// {x, y, z} object of a vector (for `mean_N`, `peak_N`, ...).
nlohmann::json xyz(const Eigen::Vector3d& value);

/// Pretty-printed JSON text. Throws robomill::NumericalError naming the key
/// path of the first NaN or infinity: robomill never reports a non-finite result.
std::string summary_text(const nlohmann::json& summary);

}  // namespace robomill::io
