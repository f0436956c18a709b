#include "robomill/robot/posture_interpolation.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace robomill::robot {
namespace {

std::string posture_name(std::size_t i) {
  return "posture " + std::to_string(i + 1);
}

void check_options(const IdwOptions& options, Eigen::Index joints) {
  if (!std::isfinite(options.power) || !(options.power > 0.0)) {
    throw std::invalid_argument("inverse-distance power must be positive and finite, got " +
                                std::to_string(options.power));
  }
  if (!std::isfinite(options.exact_tolerance_rad) || options.exact_tolerance_rad < 0.0)
    throw std::invalid_argument("exact-match tolerance must be finite and non-negative");
  if (options.joint_weights.size() == 0)
    return;
  if (options.joint_weights.size() != joints) {
    throw std::invalid_argument("joint weights: " + std::to_string(options.joint_weights.size()) +
                                " given for postures of " + std::to_string(joints) + " joints");
  }
  for (Eigen::Index j = 0; j < joints; ++j) {
    const double w = options.joint_weights[j];
    if (!std::isfinite(w) || w < 0.0) {
      throw std::invalid_argument("joint weights: joint " + std::to_string(j + 1) +
                                  " must be finite and non-negative");
    }
  }
  if (!(options.joint_weights.maxCoeff() > 0.0))
    throw std::invalid_argument("joint weights: at least one must be positive");
}

}  // namespace

IdwResult idw_weights(const std::vector<Eigen::VectorXd>& postures_rad,
                      const Eigen::VectorXd& query_rad, const IdwOptions& options) {
  if (postures_rad.empty())
    throw std::invalid_argument("posture library is empty: at least one measured posture needed");
  const Eigen::Index joints = query_rad.size();
  if (joints == 0)
    throw std::invalid_argument("query posture has no joints");
  if (!query_rad.allFinite())
    throw std::invalid_argument("query posture has non-finite joint angles");
  check_options(options, joints);
  const std::size_t s = postures_rad.size();
  Eigen::VectorXd distance(static_cast<Eigen::Index>(s));
  for (std::size_t i = 0; i < s; ++i) {
    const Eigen::VectorXd& q = postures_rad[i];
    if (q.size() != joints) {
      throw std::invalid_argument(posture_name(i) + " has " + std::to_string(q.size()) +
                                  " joints but the query has " + std::to_string(joints));
    }
    if (!q.allFinite())
      throw std::invalid_argument(posture_name(i) + " has non-finite joint angles");
    Eigen::VectorXd delta = query_rad - q;
    if (options.joint_weights.size() != 0)
      delta = delta.cwiseProduct(options.joint_weights);
    distance[static_cast<Eigen::Index>(i)] = delta.norm();  // 001 Eq 17
  }

  IdwResult result;
  result.weights = Eigen::VectorXd::Zero(distance.size());
  Eigen::Index nearest = 0;
  const double d_min = distance.minCoeff(&nearest);
  if (d_min <= options.exact_tolerance_rad) {
    // A measured posture: Eq 18 tends to 1 for it and 0 for the others.
    result.weights[nearest] = 1.0;
    result.exact_index = static_cast<int>(nearest);
    return result;
  }
  // 001 Eq 18, written as (d_min / d_i)^p / Σ (d_min / d_j)^p: the same ratio,
  // but every term lies in (0, 1] so nothing overflows for tiny distances.
  for (Eigen::Index i = 0; i < distance.size(); ++i)
    result.weights[i] = std::pow(d_min / distance[i], options.power);
  result.weights /= result.weights.sum();  // the sum is ≥ 1 (nearest term)
  return result;
}

IdwResult idw_interpolate(const std::vector<Eigen::VectorXd>& postures_rad,
                          const std::vector<Eigen::VectorXd>& payloads,
                          const Eigen::VectorXd& query_rad, const IdwOptions& options) {
  if (payloads.size() != postures_rad.size()) {
    throw std::invalid_argument(std::to_string(payloads.size()) + " payloads given for " +
                                std::to_string(postures_rad.size()) +
                                " postures: one payload per posture needed");
  }
  IdwResult result = idw_weights(postures_rad, query_rad, options);
  const Eigen::Index length = payloads.front().size();
  for (std::size_t i = 0; i < payloads.size(); ++i) {
    if (payloads[i].size() != length) {
      throw std::invalid_argument("payload of " + posture_name(i) + " has " +
                                  std::to_string(payloads[i].size()) + " values, that of " +
                                  posture_name(0) + " " + std::to_string(length));
    }
    if (!payloads[i].allFinite())
      throw std::invalid_argument("payload of " + posture_name(i) + " has non-finite values");
  }
  if (result.exact_index >= 0) {
    result.value = payloads[static_cast<std::size_t>(result.exact_index)];
    return result;
  }
  result.value = Eigen::VectorXd::Zero(length);  // 001 Eq 16
  for (std::size_t i = 0; i < payloads.size(); ++i)
    result.value += result.weights[static_cast<Eigen::Index>(i)] * payloads[i];
  return result;
}

std::vector<DirectionalModeParameters> interpolate_modal_tables(
    const std::vector<Eigen::VectorXd>& postures_rad,
    const std::vector<std::vector<DirectionalModeParameters>>& tables,
    const Eigen::VectorXd& query_rad, const IdwOptions& options, StiffnessAveraging stiffness) {
  if (tables.size() != postures_rad.size()) {
    throw std::invalid_argument(std::to_string(tables.size()) + " modal tables given for " +
                                std::to_string(postures_rad.size()) + " postures");
  }
  if (tables.empty())
    throw std::invalid_argument("posture library is empty: at least one measured posture needed");
  const std::size_t modes = tables.front().size();
  if (modes == 0)
    throw std::invalid_argument("modal table of posture 1 has no modes");
  // Pack each table as [fn…, ζ…, k or 1/k…] so one generic call averages all.
  std::vector<Eigen::VectorXd> payloads;
  for (std::size_t i = 0; i < tables.size(); ++i) {
    const auto& table = tables[i];
    if (table.size() != modes) {
      throw std::invalid_argument("modal table of " + posture_name(i) + " has " +
                                  std::to_string(table.size()) + " modes, that of posture 1 " +
                                  std::to_string(modes) + ": every posture needs the same modes");
    }
    Eigen::VectorXd packed(static_cast<Eigen::Index>(3 * modes));
    for (std::size_t m = 0; m < modes; ++m) {
      const auto& mode = table[m];
      const std::string which = posture_name(i) + ", mode " + std::to_string(m + 1) + ": ";
      if (mode.axis != tables.front()[m].axis) {
        throw std::invalid_argument(
            which + "axis " + std::to_string(mode.axis) + " differs from posture 1's " +
            std::to_string(tables.front()[m].axis) + ": modes must be listed in the same order");
      }
      if (mode.axis < 0 || mode.axis > 2)
        throw std::invalid_argument(which + "axis must be 0, 1 or 2");
      if (!std::isfinite(mode.natural_frequency_hz) || !(mode.natural_frequency_hz > 0.0))
        throw std::invalid_argument(which + "natural frequency must be positive and finite");
      if (!(mode.damping_ratio > 0.0 && mode.damping_ratio < 1.0))
        throw std::invalid_argument(which + "damping ratio must lie in (0, 1)");
      if (!std::isfinite(mode.stiffness_n_per_m) || !(mode.stiffness_n_per_m > 0.0))
        throw std::invalid_argument(which + "modal stiffness must be positive and finite");
      const auto mi = static_cast<Eigen::Index>(m);
      const auto mm = static_cast<Eigen::Index>(modes);
      packed[mi] = mode.natural_frequency_hz;
      packed[mm + mi] = mode.damping_ratio;
      packed[2 * mm + mi] = stiffness == StiffnessAveraging::kCompliance
                                ? 1.0 / mode.stiffness_n_per_m
                                : mode.stiffness_n_per_m;
    }
    payloads.push_back(std::move(packed));
  }
  const IdwResult mean = idw_interpolate(postures_rad, payloads, query_rad, options);
  if (mean.exact_index >= 0)
    return tables[static_cast<std::size_t>(mean.exact_index)];  // bit-exact, no 1/(1/k)
  std::vector<DirectionalModeParameters> result(modes);
  const auto mm = static_cast<Eigen::Index>(modes);
  for (std::size_t m = 0; m < modes; ++m) {
    const auto mi = static_cast<Eigen::Index>(m);
    result[m].axis = tables.front()[m].axis;
    result[m].natural_frequency_hz = mean.value[mi];
    result[m].damping_ratio = mean.value[mm + mi];
    const double k_or_c = mean.value[2 * mm + mi];  // a convex mean of positives: > 0
    result[m].stiffness_n_per_m =
        stiffness == StiffnessAveraging::kCompliance ? 1.0 / k_or_c : k_or_c;
  }
  return result;
}

PostureFrf interpolate_frfs(const std::vector<Eigen::VectorXd>& postures_rad,
                            const std::vector<PostureFrf>& frfs, const Eigen::VectorXd& query_rad,
                            const IdwOptions& options) {
  if (frfs.size() != postures_rad.size()) {
    throw std::invalid_argument(std::to_string(frfs.size()) + " FRF sets given for " +
                                std::to_string(postures_rad.size()) + " postures");
  }
  if (frfs.empty())
    throw std::invalid_argument("posture library is empty: at least one measured posture needed");
  const PostureFrf& first = frfs.front();
  const Eigen::Index lines = first.frequency_hz.size();
  const Eigen::Index channels = first.receptance_m_per_n.cols();
  if (lines == 0 || channels == 0)
    throw std::invalid_argument("FRF of posture 1 is empty");
  if (!first.frequency_hz.allFinite())
    throw std::invalid_argument("FRF of posture 1 has non-finite frequencies");
  const double grid_scale = first.frequency_hz.cwiseAbs().maxCoeff();
  std::vector<Eigen::VectorXd> payloads;
  for (std::size_t i = 0; i < frfs.size(); ++i) {
    const PostureFrf& frf = frfs[i];
    const std::string which = "FRF of " + posture_name(i) + ": ";
    if (frf.receptance_m_per_n.rows() != frf.frequency_hz.size())
      throw std::invalid_argument(which + "needs one row of values per frequency");
    if (frf.frequency_hz.size() != lines || frf.receptance_m_per_n.cols() != channels) {
      throw std::invalid_argument(which + "has " + std::to_string(frf.frequency_hz.size()) +
                                  " lines × " + std::to_string(frf.receptance_m_per_n.cols()) +
                                  " channels, posture 1 " + std::to_string(lines) + " × " +
                                  std::to_string(channels));
    }
    if (!frf.frequency_hz.allFinite() ||
        (frf.frequency_hz - first.frequency_hz).cwiseAbs().maxCoeff() > 1e-9 * grid_scale)
      throw std::invalid_argument(which + "frequency grid differs from posture 1's");
    if (!frf.receptance_m_per_n.allFinite())
      throw std::invalid_argument(which + "has non-finite values");
    // Real parts then imaginary parts, column-major: the complex average of
    // Eq 16 is the average of each part with the same real weights.
    Eigen::VectorXd packed(2 * lines * channels);
    packed.head(lines * channels) = frf.receptance_m_per_n.real().reshaped();
    packed.tail(lines * channels) = frf.receptance_m_per_n.imag().reshaped();
    payloads.push_back(std::move(packed));
  }
  const IdwResult mean = idw_interpolate(postures_rad, payloads, query_rad, options);
  if (mean.exact_index >= 0)
    return frfs[static_cast<std::size_t>(mean.exact_index)];
  PostureFrf result;
  result.frequency_hz = first.frequency_hz;
  result.receptance_m_per_n.resize(lines, channels);
  result.receptance_m_per_n.real() = mean.value.head(lines * channels).reshaped(lines, channels);
  result.receptance_m_per_n.imag() = mean.value.tail(lines * channels).reshaped(lines, channels);
  return result;
}

}  // namespace robomill::robot
