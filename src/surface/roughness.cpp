// Roughness of a Z-map; see roughness.hpp.

#include "robomill/surface/roughness.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "robomill/simulation/spectrum.hpp"

namespace robomill::surface {

ProfileRoughness profile_roughness(std::span<const double> z) {
  ProfileRoughness r;
  const std::size_t n = z.size();
  if (n < 2)
    return r;
  // Least-squares line over the sample index.
  double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = static_cast<double>(i);
    sx += x;
    sy += z[i];
    sxx += x * x;
    sxy += x * z[i];
  }
  const double count = static_cast<double>(n);
  const double slope = (count * sxy - sx * sy) / (count * sxx - sx * sx);
  const double intercept = (sy - slope * sx) / count;
  double sum_abs = 0.0, sum_sq = 0.0, lo = 1e300, hi = -1e300;
  for (std::size_t i = 0; i < n; ++i) {
    const double e = z[i] - (intercept + slope * static_cast<double>(i));
    sum_abs += std::abs(e);
    sum_sq += e * e;
    lo = std::min(lo, e);
    hi = std::max(hi, e);
  }
  r.ra_m = sum_abs / count;
  r.rq_m = std::sqrt(sum_sq / count);
  r.rz_m = hi - lo;
  return r;
}

std::vector<double> feed_line(const ZMap& map, int j) {
  std::vector<double> line(static_cast<std::size_t>(map.grid.nodes_x()));
  for (int i = 0; i < map.grid.nodes_x(); ++i)
    line[static_cast<std::size_t>(i)] = map.at(i, j);
  return line;
}

std::vector<double> stepover_line(const ZMap& map, int i) {
  std::vector<double> line(static_cast<std::size_t>(map.grid.nodes_y()));
  for (int j = 0; j < map.grid.nodes_y(); ++j)
    line[static_cast<std::size_t>(j)] = map.at(i, j);
  return line;
}

SurfaceRoughness roughness(const ZMap& map) {
  SurfaceRoughness s;
  const int nx = map.grid.nodes_x(), ny = map.grid.nodes_y();
  for (int j = 0; j < ny; ++j) {
    const ProfileRoughness p = profile_roughness(feed_line(map, j));
    s.feed.ra_m += p.ra_m / ny;
    s.feed.rq_m += p.rq_m / ny;
    s.feed.rz_m += p.rz_m / ny;
  }
  s.feed_mark_m = s.feed.rz_m;
  // Texture interval: the mean spectrum of the feed lines (x as "time").
  if (nx >= 8) {
    simulation::AmplitudeSpectrum mean;
    for (int j = 0; j < ny; ++j) {
      const simulation::AmplitudeSpectrum line =
          simulation::amplitude_spectrum(feed_line(map, j), map.grid.dx(), 4);
      if (mean.amplitude.empty())
        mean = line;
      else
        for (std::size_t k = 0; k < line.amplitude.size(); ++k)
          mean.amplitude[k] += line.amplitude[k];
    }
    const double length_m = map.grid.length_x_m;
    const double cycles_per_m =
        simulation::peak_frequency_hz(mean, 2.0 / length_m, 0.5 / map.grid.dx());
    s.feed_texture_interval_m = cycles_per_m > 0.0 ? 1.0 / cycles_per_m : 0.0;
  }
  for (int i = 0; i < nx; ++i) {
    const std::vector<double> line = stepover_line(map, i);
    const ProfileRoughness p = profile_roughness(line);
    s.stepover.ra_m += p.ra_m / nx;
    s.stepover.rq_m += p.rq_m / nx;
    s.stepover.rz_m += p.rz_m / nx;
    const auto [lo, hi] = std::minmax_element(line.begin(), line.end());
    s.max_residual_m = std::max(s.max_residual_m, *hi - *lo);
  }
  // Least-squares plane z = c0 + c1 x + c2 y over the nodes.
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const Eigen::Vector3d row(1.0, i, j);
      normal += row * row.transpose();
      rhs += row * map.at(i, j);
    }
  const Eigen::Vector3d c = normal.ldlt().solve(rhs);
  double sum_abs = 0.0, sum_sq = 0.0, lo = 1e300, hi = -1e300;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double e = map.at(i, j) - (c(0) + c(1) * i + c(2) * j);
      sum_abs += std::abs(e);
      sum_sq += e * e;
      lo = std::min(lo, e);
      hi = std::max(hi, e);
    }
  const double count = static_cast<double>(nx) * ny;
  s.sa_m = sum_abs / count;
  s.sq_m = std::sqrt(sum_sq / count);
  s.sz_m = hi - lo;
  return s;
}

}  // namespace robomill::surface
