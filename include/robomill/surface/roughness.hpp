#pragma once
// Roughness of a Z-map (001 §3.3, Table 3): profile parameters Ra, Rq along
// the feed (x) and the step-over (y) lines, areal Sa, Sq, Sz, and the
// residual height between passes.
//
// Profiles: each line's mean line is removed (least squares, a straight line
// over the line) before Ra = mean |z|, Rq = √(mean z²), Rz = max − min (the
// line's peak-to-valley). Areal parameters after removing the least-squares
// plane: Sa = mean |z|, Sq = √(mean z²), Sz = max − min. No filter is applied
// (the 2 mm patches of 001 are shorter than the usual cut-off of 0.8 mm × 5).

#include <span>

#include "robomill/surface/topography.hpp"

namespace robomill::surface {

struct ProfileRoughness {
  double ra_m = 0.0, rq_m = 0.0, rz_m = 0.0;
};

/// Ra, Rq, Rz of equally spaced samples after removing their least-squares line.
ProfileRoughness profile_roughness(std::span<const double> z_m);

struct SurfaceRoughness {
  ProfileRoughness feed;      ///< mean over the lines along x (the feed)
  ProfileRoughness stepover;  ///< mean over the lines along y (across the passes)
  double sa_m = 0.0, sq_m = 0.0, sz_m = 0.0;
  /// Largest peak-to-valley of a step-over line: the residual height between
  /// passes (the scallop without vibration).
  double max_residual_m = 0.0;
  /// Mean peak-to-valley of the feed lines (the feed marks without vibration).
  double feed_mark_m = 0.0;
  /// The texture interval along the feed (001 §3.3): the wavelength of the
  /// largest peak of the feed lines' mean amplitude spectrum, between two
  /// cells and half the patch; 0 when the lines are flat. Without vibration
  /// the feed per tooth (per revolution with runout); a vibration locked to
  /// every second revolution doubles the latter.
  double feed_texture_interval_m = 0.0;
};

SurfaceRoughness roughness(const ZMap& map);

/// The heights of node row j (along x) and node column i (along y).
std::vector<double> feed_line(const ZMap& map, int j);
std::vector<double> stepover_line(const ZMap& map, int i);

}  // namespace robomill::surface
