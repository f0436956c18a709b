#pragma once
// Stability lobe diagrams from the time-domain methods (floquet.hpp): the
// limiting axial depth at each spindle speed (boundary mode) or the spectral
// radius over a speed x depth grid (map mode). Speeds are independent work
// items and run in parallel, one Floquet workspace per thread.

#include <optional>
#include <string>
#include <vector>

#include "robomill/stability/floquet.hpp"
#include "robomill/stability/regenerative_model.hpp"

namespace robomill::stability {

/// Ahmadi's linear-equivalent process damping inside the time-domain methods
/// (000 Eq 18-19): C_eq = K_sp w² dz / (4 v), v = R Ω.
struct LinearProcessDamping {
  double indentation_n_per_m3 = 1.5e14;  ///< K_sp
  double wear_land_m = 40e-6;            ///< w
  double friction = 0.3;                 ///< μ
};

struct LobeOptions {
  FloquetMethod method = FloquetMethod::fdm;
  int steps = 40;                 ///< discretization: steps per tooth period
  double depth_max_m = 0.0;       ///< search range (0, depth_max]
  double depth_tolerance = 1e-3;  ///< relative width of the final bracket
  int coarse_points = 24;  ///< scan points before refinement (finds islands ≥ depth_max/24)
  /// Probe the limit extrapolated from the previous speeds first. Off by
  /// default: on the benchmark's 200-400 speeds it saves at most 7 % of the
  /// solves and costs up to 9 % elsewhere (the coarse island scan dominates).
  bool continuation = false;
  int threads = 0;                                      ///< 0: all cores
  std::optional<LinearProcessDamping> process_damping;  ///< none by default
};

/// One point of the stability boundary.
struct LobePoint {
  double spindle_rad_s = 0.0;
  /// Smallest unstable depth (to the tolerance), or depth_max when the cut is
  /// stable over the whole search range (`limited` false).
  double depth_limit_m = 0.0;
  bool limited = false;
  double chatter_frequency_hz = 0.0;  ///< 0 when not limited
  std::string bifurcation = "none";   ///< "hopf", "flip" (period doubling), "fold" or "none"
  int evaluations = 0;                ///< Floquet solves spent on this speed
};

/// The limiting depth at each speed, the shallowest depth where the spectral
/// radius reaches 1: optional continuation probes either side of the limit
/// extrapolated from the previous speeds bracket the crossing; a coarse scan of (0, depth_max] in
/// `coarse_points` steps below it finds any shallower crossing (islands, the next lobe); a
/// safeguarded regula falsi (Illinois) narrows the bracket to
/// `depth_tolerance`. Speeds are processed in fixed chunks of 16 that continue
/// from speed to speed, in parallel, so results are in the order of
/// `spindle_rad_s` and do not depend on the thread count.
std::vector<LobePoint> stability_boundary(const RegenerativeModel& model,
                                          const std::vector<double>& spindle_rad_s,
                                          const LobeOptions& options);

/// Spectral radius at every (speed, depth): row i is speed i, column j depth j.
struct StabilityMap {
  std::vector<double> spindle_rad_s;
  std::vector<double> depth_m;
  Eigen::MatrixXd spectral_radius;
};
StabilityMap stability_map(const RegenerativeModel& model, const std::vector<double>& spindle_rad_s,
                           const std::vector<double>& depth_m, const LobeOptions& options);

/// `count` speeds evenly spaced over [from, to] (one speed when count is 1).
std::vector<double> linear_range(double from, double to, int count);

}  // namespace robomill::stability
