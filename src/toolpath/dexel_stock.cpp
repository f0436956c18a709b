#include "robomill/toolpath/dexel_stock.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace robomill::toolpath {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Material shorter than this along a ray is dropped: it is below the float
// resolution of a ray coordinate on a metre-sized stock (6e-8 m), so keeping
// it would only keep rounding dust.
constexpr float kMinLength = 1e-7f;
constexpr DexelInterval kEmpty{0.0f, -1.0f};

bool is_empty(const DexelInterval& interval) noexcept {
  return !(interval.to_m > interval.from_m);
}

// A closed interval of a line parameter; empty when hi < lo.
struct Span {
  double lo = kInf, hi = -kInf;
  bool empty() const noexcept { return !(hi >= lo); }
  void hull(const Span& other) noexcept {
    if (other.empty())
      return;
    lo = std::min(lo, other.lo);
    hi = std::max(hi, other.hi);
  }
};

Span intersect(const Span& a, const Span& b) noexcept {
  return {std::max(a.lo, b.lo), std::min(a.hi, b.hi)};
}

// Parameters t with A t² + 2 B t + C ≤ 0, A ≥ 0. A line (almost) parallel to a
// cylinder's axis (A ≈ 0) is inside everywhere or nowhere.
Span quadratic_at_most_zero(double a, double b, double c) noexcept {
  if (a <= 1e-12)
    return c <= 0.0 ? Span{-kInf, kInf} : Span{};
  const double discriminant = b * b - a * c;
  if (discriminant < 0.0)
    return {};
  const double root = std::sqrt(discriminant);
  return {(-b - root) / a, (-b + root) / a};
}

// Parameters t with lo ≤ h0 + t k ≤ hi.
Span slab(double h0, double k, double lo, double hi) noexcept {
  if (std::abs(k) < 1e-14)
    return (h0 >= lo && h0 <= hi) ? Span{-kInf, kInf} : Span{};
  const double t1 = (lo - h0) / k, t2 = (hi - h0) / k;
  return {std::min(t1, t2), std::max(t1, t2)};
}

// The line p + t e inside the capsule of radius R around the segment c0 → c1
// (the solid a ball sweeps along the segment): the hull of the two end balls
// and the cylinder between the end planes (the capsule is convex, so the
// three spans, where not empty, overlap into one).
template <int N>
Span line_capsule(const Eigen::Matrix<double, N, 1>& p, const Eigen::Matrix<double, N, 1>& e,
                  const Eigen::Matrix<double, N, 1>& c0, const Eigen::Matrix<double, N, 1>& c1,
                  double radius) noexcept {
  Span out;
  const double ee = e.squaredNorm();
  for (const auto* c : {&c0, &c1}) {
    const Eigen::Matrix<double, N, 1> w = p - *c;
    out.hull(quadratic_at_most_zero(ee, w.dot(e), w.squaredNorm() - radius * radius));
  }
  const Eigen::Matrix<double, N, 1> s = c1 - c0;
  const double length2 = s.squaredNorm();
  if (length2 > 0.0) {
    const Eigen::Matrix<double, N, 1> w = p - c0;
    const double ws = w.dot(s) / length2, es = e.dot(s) / length2;
    const Eigen::Matrix<double, N, 1> w_perp = w - ws * s;
    const Eigen::Matrix<double, N, 1> e_perp = e - es * s;
    const Span cylinder = quadratic_at_most_zero(e_perp.squaredNorm(), w_perp.dot(e_perp),
                                                 w_perp.squaredNorm() - radius * radius);
    out.hull(intersect(cylinder, slab(ws, es, 0.0, 1.0)));
  }
  return out;
}

// The line q + t e_g inside a bull nose's corner: the points within r_c of
// the disc of radius R − r_c at height r_c (a torus filled in), below that
// height. The distance to a convex set is a convex function of t, so the
// span where it is at most r_c is one interval: its minimum by golden-section
// search, then each end by bisection, to 1e-12 of the span searched (the
// torus's quartic has no closed form worth its rounding).
Span line_torus_corner(const Eigen::Vector3d& w, int g, const Eigen::Vector3d& a, double radius,
                       double corner, double length) noexcept {
  const double inner = radius - corner;
  const double top = std::min(corner, length);
  // Signed excess of the distance to the disc over r_c at w + t e_g (w from
  // the tip); points above the corner's top count as outside.
  auto excess = [&](double t) {
    Eigen::Vector3d p = w;
    p[g] += t;
    const double h = p.dot(a);
    const double rho = (p - h * a).norm();
    const double out_radial = std::max(0.0, rho - inner);
    const double dh = h - corner;
    return std::max(std::sqrt(dh * dh + out_radial * out_radial) - corner, h - top);
  };
  // The corner lies within R of its centre (tip + r_c a): search there.
  const Eigen::Vector3d wc = w - corner * a;
  const Span bound = quadratic_at_most_zero(1.0, wc[g], wc.squaredNorm() - radius * radius);
  if (bound.empty())
    return {};
  constexpr double kGolden = 0.6180339887498949;
  double lo = bound.lo, hi = bound.hi;
  double x1 = hi - kGolden * (hi - lo), x2 = lo + kGolden * (hi - lo);
  double f1 = excess(x1), f2 = excess(x2);
  const double tolerance = 1e-12 * std::max(1.0, bound.hi - bound.lo);
  while (hi - lo > tolerance && (f1 > 0.0 && f2 > 0.0)) {
    if (f1 < f2) {
      hi = x2;
      x2 = x1;
      f2 = f1;
      x1 = hi - kGolden * (hi - lo);
      f1 = excess(x1);
    } else {
      lo = x1;
      x1 = x2;
      f1 = f2;
      x2 = lo + kGolden * (hi - lo);
      f2 = excess(x2);
    }
  }
  double inside = 0.0;
  if (f1 <= 0.0) {
    inside = x1;
  } else if (f2 <= 0.0) {
    inside = x2;
  } else {
    return {};
  }
  auto bisect = [&](double in, double out) {
    while (std::abs(out - in) > tolerance) {
      const double mid = 0.5 * (in + out);
      (excess(mid) <= 0.0 ? in : out) = mid;
    }
    return in;
  };
  return {bisect(inside, bound.lo), bisect(inside, bound.hi)};
}

// The axis-aligned line q + t e_g (g ∈ {0, 1, 2}) inside one cutter instance
// (tip, unit axis a): the cylinder part (radius R, heights [h_corner, L]) and,
// for a ball end, the lower half ball centred at height R; for a bull nose
// the torus corner (line_torus_corner). The solid is convex, so the two spans
// overlap into one.
Span line_cutter(const Eigen::Vector3d& q, int g, const CutterShape& cutter,
                 const Eigen::Vector3d& tip, const Eigen::Vector3d& a) noexcept {
  const double radius = cutter.radius_m, length = cutter.length_m;
  const double corner = cutter.is_ball() ? radius : cutter.corner_radius_m;
  const Eigen::Vector3d w = q - tip;
  const double h0 = w.dot(a), ag = a[g];
  const Eigen::Vector3d w_perp = w - h0 * a;
  Span out = intersect(
      quadratic_at_most_zero(1.0 - ag * ag, w_perp[g], w_perp.squaredNorm() - radius * radius),
      slab(h0, ag, corner, length));
  if (cutter.is_ball()) {
    const Eigen::Vector3d ws = w - radius * a;
    out.hull(intersect(quadratic_at_most_zero(1.0, ws[g], ws.squaredNorm() - radius * radius),
                       slab(h0, ag, 0.0, std::min(corner, length))));
  } else if (corner > 0.0) {
    out.hull(line_torus_corner(w, g, a, radius, corner, length));
  }
  return out;
}

// Cell indices whose centres lie in [lo, hi] along one axis.
struct IndexRange {
  int first = 0, last = -1;
};
IndexRange centres_within(double lo, double hi, double min, double cell, int count) noexcept {
  if (!(hi >= lo))
    return {};
  const double f = std::ceil((lo - min) / cell - 0.5), l = std::floor((hi - min) / cell - 0.5);
  IndexRange range;
  range.first = static_cast<int>(std::max(0.0, f));
  range.last = static_cast<int>(std::min(static_cast<double>(count - 1), l));
  return range;
}

}  // namespace

// Ray storage operations (the grids are private to DexelStock).
struct DexelAccess {
  using Grid = DexelStock::Grid;

  struct Intervals {
    const DexelInterval* data;
    std::size_t size;
  };
  static Intervals intervals(const Grid& grid, std::size_t ray) noexcept {
    if (const std::uint32_t slot = grid.slot[ray]; slot != 0) {
      const auto& list = grid.overflow[slot - 1];
      return {list.data(), list.size()};
    }
    const DexelInterval& only = grid.first[ray];
    return {&only, is_empty(only) ? 0u : 1u};
  }

  static std::uint32_t take_slot(Grid& grid) {
    if (!grid.free_slots.empty()) {
      const std::uint32_t slot = grid.free_slots.back();
      grid.free_slots.pop_back();
      return slot;
    }
    grid.overflow.emplace_back();
    return static_cast<std::uint32_t>(grid.overflow.size());
  }

  // Back to `first` once a split ray is down to one interval; the overflow
  // vector keeps its capacity in the pool for the next split.
  static void settle(Grid& grid, std::size_t ray) {
    const std::uint32_t slot = grid.slot[ray];
    auto& list = grid.overflow[slot - 1];
    if (list.size() > 1)
      return;
    grid.first[ray] = list.empty() ? kEmpty : list.front();
    list.clear();
    grid.slot[ray] = 0;
    grid.free_slots.push_back(slot);
  }

  static void assign(Grid& grid, std::size_t ray, const std::vector<DexelInterval>& list) {
    if (grid.slot[ray] != 0) {
      grid.overflow[grid.slot[ray] - 1].clear();
      grid.free_slots.push_back(grid.slot[ray]);
      grid.slot[ray] = 0;
    }
    if (list.size() <= 1) {
      grid.first[ray] = list.empty() ? kEmpty : list.front();
      return;
    }
    const std::uint32_t slot = take_slot(grid);
    grid.overflow[slot - 1] = list;
    grid.slot[ray] = slot;
  }

  // Removes [a, b] (metres along the ray from the box's min) from a ray.
  static bool subtract(Grid& grid, std::size_t ray, float a, float b) {
    if (!(b > a))
      return false;
    if (grid.slot[ray] == 0) {
      DexelInterval& only = grid.first[ray];
      if (is_empty(only) || b <= only.from_m || a >= only.to_m)
        return false;
      const bool keep_left = a - only.from_m > kMinLength;
      const bool keep_right = only.to_m - b > kMinLength;
      if (keep_left && keep_right) {
        const std::uint32_t slot = take_slot(grid);
        auto& list = grid.overflow[slot - 1];
        list.clear();
        list.push_back({only.from_m, a});
        list.push_back({b, only.to_m});
        grid.slot[ray] = slot;
      } else if (keep_left) {
        only.to_m = a;
      } else if (keep_right) {
        only.from_m = b;
      } else {
        only = kEmpty;
      }
      return true;
    }
    auto& list = grid.overflow[grid.slot[ray] - 1];
    const auto lo = std::partition_point(list.begin(), list.end(),
                                         [a](const DexelInterval& i) { return i.to_m <= a; });
    const auto hi =
        std::partition_point(lo, list.end(), [b](const DexelInterval& i) { return i.from_m < b; });
    if (lo == hi)
      return false;
    const DexelInterval left{lo->from_m, a}, right{b, (hi - 1)->to_m};
    const bool keep_left = left.to_m - left.from_m > kMinLength;
    const bool keep_right = right.to_m - right.from_m > kMinLength;
    const std::ptrdiff_t at = lo - list.begin(), overlapped = hi - lo;
    const std::ptrdiff_t kept = (keep_left ? 1 : 0) + (keep_right ? 1 : 0);
    if (kept > overlapped) {  // one interval split in two
      list[at] = left;
      list.insert(list.begin() + at + 1, right);
    } else {
      std::ptrdiff_t out = at;
      if (keep_left)
        list[out++] = left;
      if (keep_right)
        list[out++] = right;
      list.erase(list.begin() + out, list.begin() + at + overlapped);
    }
    settle(grid, ray);
    return true;
  }

  // Signed distance along the ray from `t` to the nearest end of material
  // (positive inside), clamped to ±cap.
  static double depth(const Grid& grid, std::size_t ray, double t, double cap) noexcept {
    const Intervals list = intervals(grid, ray);
    double best = -cap;
    for (std::size_t k = 0; k < list.size; ++k) {
      const double from = list.data[k].from_m, to = list.data[k].to_m;
      if (t < from)
        return std::max(best, t - from);
      if (t <= to)
        return std::min(cap, std::min(t - from, to - t));
      best = std::max(best, to - t);
    }
    return best;
  }

  static std::size_t remove_line(DexelStock& stock, int g, int iu, int iv, const Span& span) {
    Grid& grid = stock.grids_[g];
    const double extent = stock.box_.max_m[g] - stock.box_.min_m[g];
    const double lo = std::max(span.lo - stock.box_.min_m[g], 0.0);
    const double hi = std::min(span.hi - stock.box_.min_m[g], extent);
    if (!(hi > lo))
      return 0;
    const std::size_t ray = static_cast<std::size_t>(iv) * grid.count_u + iu;
    return subtract(grid, ray, static_cast<float>(lo), static_cast<float>(hi)) ? 1 : 0;
  }

  // The cells of each axis whose centres lie in the box a vertical cutter
  // sweeps from tip0 to tip1 (R around the segment, up to L above it),
  // clipped to the stock; empty when the sweep misses the stock.
  static std::optional<std::array<IndexRange, 3>> vertical_sweep_cells(
      const DexelStock& stock, const CutterShape& cutter, const Eigen::Vector3d& tip0,
      const Eigen::Vector3d& tip1) {
    const StockBox& box = stock.box_;
    const double radius = cutter.radius_m;
    Eigen::Vector3d lo = tip0.cwiseMin(tip1) - Eigen::Vector3d(radius, radius, 0.0);
    Eigen::Vector3d hi = tip0.cwiseMax(tip1) + Eigen::Vector3d(radius, radius, cutter.length_m);
    lo = lo.cwiseMax(box.min_m);
    hi = hi.cwiseMin(box.max_m);
    if ((hi.array() < lo.array()).any())
      return std::nullopt;
    std::array<IndexRange, 3> range;
    for (int i = 0; i < 3; ++i)
      range[i] = centres_within(lo[i], hi[i], box.min_m[i], stock.cell_m_[i], stock.counts_[i]);
    return range;
  }

  // The exact sweep of a bull nose whose axis stays +z along a level move
  // (tip0 and tip1 at one height): on each horizontal plane at height h above
  // the tip the cutter's section is a disc of radius r(h) (the torus's below
  // r_c, R above), so it sweeps the stadium of that radius around the
  // segment; a z ray at distance ρ from the segment meets the solid from the
  // corner's height over ρ (0 inside R − r_c) up to L.
  static std::size_t sweep_bull_level(DexelStock& stock, const CutterShape& cutter,
                                      const Eigen::Vector3d& tip0, const Eigen::Vector3d& tip1) {
    const auto cells = vertical_sweep_cells(stock, cutter, tip0, tip1);
    if (!cells)
      return 0;
    const std::array<IndexRange, 3>& range = *cells;
    const double radius = cutter.radius_m, length = cutter.length_m;
    const double corner = cutter.corner_radius_m, inner = radius - corner;
    const Eigen::Vector2d c0 = tip0.head<2>(), c1 = tip1.head<2>(), s = c1 - c0;
    const double z0 = tip0.z();
    std::size_t changed = 0;
    const double length2 = s.squaredNorm();
    for (int ix = range[0].first; ix <= range[0].last; ++ix) {
      const double x = stock.cell_centre_m(0, ix);
      for (int iy = range[1].first; iy <= range[1].last; ++iy) {
        const Eigen::Vector2d p(x, stock.cell_centre_m(1, iy));
        const double tau = length2 > 0.0 ? std::clamp((p - c0).dot(s) / length2, 0.0, 1.0) : 0.0;
        const double rho = (p - (c0 + tau * s)).norm();
        if (rho > radius)
          continue;
        const double out = std::max(0.0, rho - inner);
        const double bottom = corner - std::sqrt(std::max(0.0, corner * corner - out * out));
        changed += remove_line(stock, 2, ix, iy, Span{z0 + bottom, z0 + length});
      }
    }
    for (int g = 0; g < 2; ++g) {
      const int across = 1 - g;
      const Grid& grid = stock.grids_[g];
      for (int iz = range[2].first; iz <= range[2].last; ++iz) {
        const double h = stock.cell_centre_m(2, iz) - z0;
        const double section_radius = cutter.radius_at(h);
        if (h < 0.0 || h > length || !(section_radius > 0.0))
          continue;
        for (int ia = range[across].first; ia <= range[across].last; ++ia) {
          Eigen::Vector2d p = Eigen::Vector2d::Zero(), e = Eigen::Vector2d::Zero();
          p[across] = stock.cell_centre_m(across, ia);
          e[g] = 1.0;
          const Span along = line_capsule<2>(p, e, c0, c1, section_radius);
          if (along.empty())
            continue;
          const int iu = grid.u == 2 ? iz : ia, iv = grid.v == 2 ? iz : ia;
          changed += remove_line(stock, g, iu, iv, along);
        }
      }
    }
    return changed;
  }

  // The exact sweep of a cutter whose axis stays +z from tip0 to tip1: at
  // parameter τ ∈ [0, 1] the tip is at c(τ) (x-y) and z(τ), both linear. The
  // cylinder part sweeps, on each horizontal plane, a stadium around the part
  // of the segment c(τ) whose height range covers that plane; the ball part
  // sweeps the capsule around its centres' segment.
  static std::size_t sweep_vertical(DexelStock& stock, const CutterShape& cutter,
                                    const Eigen::Vector3d& tip0, const Eigen::Vector3d& tip1) {
    const StockBox& box = stock.box_;
    const double radius = cutter.radius_m, length = cutter.length_m;
    const double corner = cutter.is_ball() ? radius : 0.0;
    const Eigen::Vector2d c0 = tip0.head<2>(), c1 = tip1.head<2>(), s = c1 - c0;
    const double z0 = tip0.z(), dz = tip1.z() - tip0.z();
    const Eigen::Vector3d ball0 = tip0 + Eigen::Vector3d(0, 0, radius);
    const Eigen::Vector3d ball1 = tip1 + Eigen::Vector3d(0, 0, radius);
    const auto cells = vertical_sweep_cells(stock, cutter, tip0, tip1);
    if (!cells)
      return 0;
    const std::array<IndexRange, 3>& range = *cells;
    // Clipped to the box, as the cells are (the rays' own limits).
    const Eigen::Vector3d lo =
        (tip0.cwiseMin(tip1) - Eigen::Vector3d(radius, radius, 0.0)).cwiseMax(box.min_m);
    const Eigen::Vector3d hi =
        (tip0.cwiseMax(tip1) + Eigen::Vector3d(radius, radius, length)).cwiseMin(box.max_m);
    std::size_t changed = 0;

    // z rays: per x column, only the y cells the stadium covers.
    for (int ix = range[0].first; ix <= range[0].last; ++ix) {
      const double x = stock.cell_centre_m(0, ix);
      const Span ys =
          line_capsule<2>(Eigen::Vector2d(x, 0.0), Eigen::Vector2d(0.0, 1.0), c0, c1, radius);
      const IndexRange iy_range = centres_within(std::max(ys.lo, lo.y()), std::min(ys.hi, hi.y()),
                                                 box.min_m.y(), stock.cell_m_[1], stock.counts_[1]);
      for (int iy = iy_range.first; iy <= iy_range.last; ++iy) {
        const Eigen::Vector2d p(x, stock.cell_centre_m(1, iy));
        const Eigen::Vector2d w = p - c0;
        const Span tau = intersect(
            quadratic_at_most_zero(s.squaredNorm(), -w.dot(s), w.squaredNorm() - radius * radius),
            Span{0.0, 1.0});
        Span z;
        if (!tau.empty()) {
          const double za = z0 + tau.lo * dz, zb = z0 + tau.hi * dz;
          z = {std::min(za, zb) + corner, std::max(za, zb) + length};
        }
        if (corner > 0.0) {
          z.hull(line_capsule<3>(Eigen::Vector3d(p.x(), p.y(), 0.0), Eigen::Vector3d::UnitZ(),
                                 ball0, ball1, radius));
        }
        if (!z.empty())
          changed += remove_line(stock, 2, ix, iy, z);
      }
    }

    // x rays (g = 0, across y) and y rays (g = 1, across x), per height. On
    // a level move the cylinder part's span on a ray does not depend on the
    // height (where the height is within the part): it is found once per ray
    // column and kept (per-thread scratch, no allocation once grown).
    const bool level = dz == 0.0;
    thread_local std::vector<Span> level_span;
    thread_local std::vector<char> level_known;
    for (int g = 0; g < 2; ++g) {
      const int across = 1 - g;
      const Grid& grid = stock.grids_[g];
      if (level) {
        const std::size_t columns =
            static_cast<std::size_t>(std::max(0, range[across].last - range[across].first + 1));
        level_span.assign(columns, Span{});
        level_known.assign(columns, 0);
      }
      for (int iz = range[2].first; iz <= range[2].last; ++iz) {
        const double z = stock.cell_centre_m(2, iz);
        // τ where the cylinder part's height range [z + corner, z + L] covers z.
        const Span tau_z = intersect(slab(z0, dz, z - length, z - corner), Span{0.0, 1.0});
        for (int ia = range[across].first; ia <= range[across].last; ++ia) {
          const double a = stock.cell_centre_m(across, ia);
          Span along;
          const std::size_t column = static_cast<std::size_t>(ia - range[across].first);
          if (level && !tau_z.empty() && level_known[column]) {
            along = level_span[column];
          } else {
            const Span tau = intersect(tau_z, slab(c0[across], s[across], a - radius, a + radius));
            if (!tau.empty()) {
              Eigen::Vector2d p = Eigen::Vector2d::Zero(), e = Eigen::Vector2d::Zero();
              p[across] = a;
              e[g] = 1.0;
              along = line_capsule<2>(p, e, c0 + tau.lo * s, c0 + tau.hi * s, radius);
            }
            if (level && !tau_z.empty()) {
              level_span[column] = along;
              level_known[column] = 1;
            }
          }
          if (corner > 0.0) {
            Eigen::Vector3d p(0.0, 0.0, z);
            p[across] = a;
            Eigen::Vector3d e = Eigen::Vector3d::Zero();
            e[g] = 1.0;
            along.hull(line_capsule<3>(p, e, ball0, ball1, radius));
          }
          if (along.empty())
            continue;
          // Grid g is indexed (u, v) = (g + 1, g + 2) mod 3.
          const int iu = grid.u == 2 ? iz : ia, iv = grid.v == 2 ? iz : ia;
          changed += remove_line(stock, g, iu, iv, along);
        }
      }
    }
    return changed;
  }
};

DexelStock::DexelStock(const StockBox& box, double resolution_m, std::size_t max_rays)
    : box_(box), resolution_m_(resolution_m) {
  if (!(resolution_m > 0.0) || !std::isfinite(resolution_m)) {
    throw std::invalid_argument("DexelStock: resolution must be positive, got " +
                                std::to_string(resolution_m));
  }
  for (int a = 0; a < 3; ++a) {
    const double extent = box.max_m[a] - box.min_m[a];
    if (!(extent > 0.0) || !std::isfinite(extent)) {
      throw std::invalid_argument("DexelStock: empty or invalid box along axis " +
                                  std::to_string(a));
    }
    const double cells = std::ceil(extent / resolution_m - 1e-9);
    if (cells > 1e8)
      throw std::invalid_argument("DexelStock: too many cells along an axis");
    counts_[a] = std::max(1, static_cast<int>(cells));
    cell_m_[a] = extent / counts_[a];
  }
  const double rays = static_cast<double>(counts_[1]) * counts_[2] +
                      static_cast<double>(counts_[0]) * counts_[2] +
                      static_cast<double>(counts_[0]) * counts_[1];
  if (rays > static_cast<double>(max_rays)) {
    throw std::invalid_argument("DexelStock: " + std::to_string(static_cast<long long>(rays)) +
                                " rays exceed the limit of " + std::to_string(max_rays));
  }
  for (int g = 0; g < 3; ++g) {
    Grid& grid = grids_[g];
    grid.axis = g;
    grid.u = (g + 1) % 3;
    grid.v = (g + 2) % 3;
    grid.count_u = counts_[grid.u];
    grid.count_v = counts_[grid.v];
    const std::size_t n = static_cast<std::size_t>(grid.count_u) * grid.count_v;
    grid.first.assign(n, DexelInterval{0.0f, static_cast<float>(box.max_m[g] - box.min_m[g])});
    grid.slot.assign(n, 0);
  }
}

DexelStock DexelStock::from_height_map(const StockBox& box, double resolution_m, int nx, int ny,
                                       const std::vector<double>& heights_m) {
  if (nx <= 0 || ny <= 0 ||
      heights_m.size() != static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny)) {
    throw std::invalid_argument("DexelStock::from_height_map: need nx × ny heights");
  }
  DexelStock stock(box, resolution_m);
  const double extent_z = box.max_m.z() - box.min_m.z();
  const double hx = (box.max_m.x() - box.min_m.x()) / nx;
  const double hy = (box.max_m.y() - box.min_m.y()) / ny;
  auto height = [&](int i, int j) {  // above box.min z, clamped to the box
    const double h = heights_m[static_cast<std::size_t>(j) * nx + i] - box.min_m.z();
    return std::clamp(std::isfinite(h) ? h : 0.0, 0.0, extent_z);
  };
  auto cell_of = [](double offset, double cell, int count) {
    return std::clamp(static_cast<int>(std::floor(offset / cell)), 0, count - 1);
  };
  Grid& gz = stock.grids_[2];
  for (int iy = 0; iy < stock.counts_[1]; ++iy) {
    const int j = cell_of(stock.cell_centre_m(1, iy) - box.min_m.y(), hy, ny);
    for (int ix = 0; ix < stock.counts_[0]; ++ix) {
      const int i = cell_of(stock.cell_centre_m(0, ix) - box.min_m.x(), hx, nx);
      const double h = height(i, j);
      gz.first[static_cast<std::size_t>(iy) * gz.count_u + ix] =
          h > 0.0 ? DexelInterval{0.0f, static_cast<float>(h)} : kEmpty;
    }
  }
  // Horizontal rays: material where the column under the ray reaches above
  // it, in runs bounded by the height map's cell edges.
  std::vector<DexelInterval> runs;
  for (int g = 0; g < 2; ++g) {
    Grid& grid = stock.grids_[g];
    const int across = 1 - g;
    const int n_along = g == 0 ? nx : ny, n_across = g == 0 ? ny : nx;
    const double h_along = g == 0 ? hx : hy, h_across = g == 0 ? hy : hx;
    for (int iz = 0; iz < stock.counts_[2]; ++iz) {
      const double z = stock.cell_centre_m(2, iz) - box.min_m.z();
      for (int ia = 0; ia < stock.counts_[across]; ++ia) {
        const int k =
            cell_of(stock.cell_centre_m(across, ia) - box.min_m[across], h_across, n_across);
        runs.clear();
        for (int m = 0; m < n_along; ++m) {
          const double h = g == 0 ? height(m, k) : height(k, m);
          if (!(h > z))
            continue;
          const float from = static_cast<float>(m * h_along),
                      to = static_cast<float>((m + 1) * h_along);
          if (!runs.empty() && runs.back().to_m >= from) {
            runs.back().to_m = to;
          } else {
            runs.push_back({from, to});
          }
        }
        const int iu = grid.u == 2 ? iz : ia, iv = grid.v == 2 ? iz : ia;
        DexelAccess::assign(grid, static_cast<std::size_t>(iv) * grid.count_u + iu, runs);
      }
    }
  }
  return stock;
}

std::size_t DexelStock::remove(const CutterShape& cutter, const Eigen::Vector3d& tip_m,
                               const Eigen::Vector3d& axis) {
  const double norm = axis.norm();
  if (!(norm > 0.0) || !(cutter.radius_m > 0.0) || !(cutter.length_m > 0.0) || !tip_m.allFinite()) {
    return 0;
  }
  const Eigen::Vector3d a = axis / norm;
  const Eigen::Vector3d top = tip_m + cutter.length_m * a;
  Eigen::Vector3d lo, hi;
  for (int i = 0; i < 3; ++i) {
    const double spread = cutter.radius_m * std::sqrt(std::max(0.0, 1.0 - a[i] * a[i]));
    lo[i] = std::max(std::min(tip_m[i], top[i]) - spread, box_.min_m[i]);
    hi[i] = std::min(std::max(tip_m[i], top[i]) + spread, box_.max_m[i]);
  }
  if ((hi.array() < lo.array()).any())
    return 0;
  std::size_t changed = 0;
  for (int g = 0; g < 3; ++g) {
    const Grid& grid = grids_[g];
    const IndexRange ru =
        centres_within(lo[grid.u], hi[grid.u], box_.min_m[grid.u], cell_m_[grid.u], grid.count_u);
    const IndexRange rv =
        centres_within(lo[grid.v], hi[grid.v], box_.min_m[grid.v], cell_m_[grid.v], grid.count_v);
    // The ray through the cell centres, parametrised by the coordinate along
    // it (q[g] = 0): line_cutter's span is then in workpiece coordinates, as
    // remove_line takes it. (A start at the box's min offset every tilted
    // removal by that min: a stock whose box does not start at 0 along an
    // axis was cut in the wrong place.)
    Eigen::Vector3d q;
    q[g] = 0.0;
    for (int iv = rv.first; iv <= rv.last; ++iv) {
      q[grid.v] = cell_centre_m(grid.v, iv);
      for (int iu = ru.first; iu <= ru.last; ++iu) {
        q[grid.u] = cell_centre_m(grid.u, iu);
        const Span span = line_cutter(q, g, cutter, tip_m, a);
        if (!span.empty())
          changed += DexelAccess::remove_line(*this, g, iu, iv, span);
      }
    }
  }
  return changed;
}

std::size_t DexelStock::remove_sweep(const CutterShape& cutter, const Eigen::Vector3d& tip0_m,
                                     const Eigen::Vector3d& axis0, const Eigen::Vector3d& tip1_m,
                                     const Eigen::Vector3d& axis1) {
  const double n0 = axis0.norm(), n1 = axis1.norm();
  if (!(n0 > 0.0) || !(n1 > 0.0) || !(cutter.radius_m > 0.0) || !(cutter.length_m > 0.0) ||
      !tip0_m.allFinite() || !tip1_m.allFinite()) {
    return 0;
  }
  const Eigen::Vector3d a0 = axis0 / n0, a1 = axis1 / n1;
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  // The exact sweep needs the ball's upper half inside the shank (L ≥ 2R).
  const bool vertical = (a0 - up).norm() < 1e-9 && (a1 - up).norm() < 1e-9 &&
                        (!cutter.is_ball() || cutter.length_m >= 2.0 * cutter.radius_m);
  if (vertical && cutter.is_bull()) {
    // A bull nose's level moves exactly; its ramps as instances (the torus
    // swept along a slanted line has no closed form here).
    if (std::abs(tip1_m.z() - tip0_m.z()) <= 1e-12)
      return DexelAccess::sweep_bull_level(*this, cutter, tip0_m, tip1_m);
  } else if (vertical) {
    return DexelAccess::sweep_vertical(*this, cutter, tip0_m, tip1_m);
  }

  // Instances: no point of the cutter moves more than a quarter cell between
  // two (the tip by |Δtip|, the far end by at most |Δtip| + θ L).
  const double angle = std::acos(std::clamp(a0.dot(a1), -1.0, 1.0));
  const double travel = (tip1_m - tip0_m).norm() + angle * cutter.length_m;
  const int steps = std::max(1, static_cast<int>(std::ceil(travel / (0.25 * resolution_m_))));
  const double sin_angle = std::sin(angle);
  std::size_t changed = 0;
  for (int i = 0; i <= steps; ++i) {
    const double tau = static_cast<double>(i) / steps;
    Eigen::Vector3d axis;
    if (sin_angle < 1e-9) {
      axis = ((1.0 - tau) * a0 + tau * a1).normalized();
    } else {  // slerp
      axis = (std::sin((1.0 - tau) * angle) * a0 + std::sin(tau * angle) * a1) / sin_angle;
    }
    changed += remove(cutter, tip0_m + tau * (tip1_m - tip0_m), axis);
  }
  return changed;
}

double DexelStock::material_depth_m(const Eigen::Vector3d& point_m,
                                    const Eigen::Vector3d& normal) const noexcept {
  const double cap = 3.0 * resolution_m_;
  if (!point_m.allFinite())
    return -cap;
  int g = 2;
  const Eigen::Vector3d n = normal.cwiseAbs();
  if (n.x() > n.y() && n.x() > n.z()) {
    g = 0;
  } else if (n.y() > n.z()) {
    g = 1;
  }
  const Grid& grid = grids_[g];
  const double t = point_m[g] - box_.min_m[g];
  const double fu = (point_m[grid.u] - box_.min_m[grid.u]) / cell_m_[grid.u] - 0.5;
  const double fv = (point_m[grid.v] - box_.min_m[grid.v]) / cell_m_[grid.v] - 0.5;
  if (fu < -2.0 || fv < -2.0 || fu > grid.count_u + 1.0 || fv > grid.count_v + 1.0)
    return -cap;
  const int iu0 = static_cast<int>(std::floor(fu)), iv0 = static_cast<int>(std::floor(fv));
  const double wu = fu - iu0, wv = fv - iv0;
  auto depth = [&](int iu, int iv) {
    if (iu < 0 || iv < 0 || iu >= grid.count_u || iv >= grid.count_v)
      return -cap;
    return DexelAccess::depth(grid, static_cast<std::size_t>(iv) * grid.count_u + iu, t, cap);
  };
  return (1.0 - wv) * ((1.0 - wu) * depth(iu0, iv0) + wu * depth(iu0 + 1, iv0)) +
         wv * ((1.0 - wu) * depth(iu0, iv0 + 1) + wu * depth(iu0 + 1, iv0 + 1));
}

std::optional<DexelStock::MaterialRun> DexelStock::material_run(
    const Eigen::Vector3d& point_m, const Eigen::Vector3d& direction) const noexcept {
  if (!point_m.allFinite() || !direction.allFinite())
    return std::nullopt;
  int g = 2;
  const Eigen::Vector3d n = direction.cwiseAbs();
  if (n.x() > n.y() && n.x() > n.z()) {
    g = 0;
  } else if (n.y() > n.z()) {
    g = 1;
  }
  const double along = direction[g];
  if (!(std::abs(along) > 0.0))
    return std::nullopt;
  const Grid& grid = grids_[g];
  const double fu = (point_m[grid.u] - box_.min_m[grid.u]) / cell_m_[grid.u] - 0.5;
  const double fv = (point_m[grid.v] - box_.min_m[grid.v]) / cell_m_[grid.v] - 0.5;
  const double t = point_m[g] - box_.min_m[g];
  // The ray nearest the point first; where it holds no material there (the
  // point within half a cell of a wall), the next nearest of the four around
  // it that does.
  const long u0 = static_cast<long>(std::floor(fu)), v0 = static_cast<long>(std::floor(fv));
  std::array<std::pair<long, long>, 4> rays{
      {{u0, v0}, {u0 + 1, v0}, {u0, v0 + 1}, {u0 + 1, v0 + 1}}};
  auto distance2 = [&](const std::pair<long, long>& ray) {
    const double du = ray.first - fu, dv = ray.second - fv;
    return du * du + dv * dv;
  };
  std::sort(rays.begin(), rays.end(),
            [&](const auto& a, const auto& b) { return distance2(a) < distance2(b); });
  for (const auto& [iu, iv] : rays) {
    if (iu < 0 || iv < 0 || iu >= grid.count_u || iv >= grid.count_v)
      continue;
    const auto list =
        DexelAccess::intervals(grid, static_cast<std::size_t>(iv) * grid.count_u + iu);
    for (std::size_t k = 0; k < list.size; ++k) {
      const double from = list.data[k].from_m, to = list.data[k].to_m;
      if (t < from)
        break;
      if (t > to)
        continue;
      // Ray distances to the interval's ends, turned into distances along
      // `direction` for a face normal to the ray.
      const double scale = 1.0 / std::abs(along);
      MaterialRun run;
      run.before_m = (along > 0.0 ? t - from : to - t) * scale;
      run.after_m = (along > 0.0 ? to - t : t - from) * scale;
      return run;
    }
  }
  return std::nullopt;
}

bool DexelStock::contains(const Eigen::Vector3d& point_m,
                          const Eigen::Vector3d& normal) const noexcept {
  return material_depth_m(point_m, normal) > 0.0;
}

double DexelStock::volume_m3() const noexcept {
  const Grid& grid = grids_[2];
  double length = 0.0;
  for (std::size_t ray = 0; ray < grid.first.size(); ++ray) {
    const auto list = DexelAccess::intervals(grid, ray);
    for (std::size_t k = 0; k < list.size; ++k) {
      length += static_cast<double>(list.data[k].to_m) - list.data[k].from_m;
    }
  }
  return length * cell_m_[0] * cell_m_[1];
}

std::vector<double> DexelStock::top_heights_m() const {
  const Grid& grid = grids_[2];
  std::vector<double> heights(grid.first.size(), box_.min_m.z());
  for (std::size_t ray = 0; ray < grid.first.size(); ++ray) {
    const auto list = DexelAccess::intervals(grid, ray);
    if (list.size > 0)
      heights[ray] = box_.min_m.z() + list.data[list.size - 1].to_m;
  }
  return heights;
}

double DexelStock::cell_centre_m(int axis, int index) const noexcept {
  return box_.min_m[axis] + (index + 0.5) * cell_m_[axis];
}

std::size_t DexelStock::memory_bytes() const noexcept {
  std::size_t bytes = 0;
  for (const Grid& grid : grids_) {
    bytes += grid.first.capacity() * sizeof(DexelInterval) +
             grid.slot.capacity() * sizeof(std::uint32_t) +
             grid.overflow.capacity() * sizeof(std::vector<DexelInterval>) +
             grid.free_slots.capacity() * sizeof(std::uint32_t);
    for (const auto& list : grid.overflow)
      bytes += list.capacity() * sizeof(DexelInterval);
  }
  return bytes;
}

}  // namespace robomill::toolpath
