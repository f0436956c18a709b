#include "robomill/toolpath/cutter_shape.hpp"

#include <algorithm>
#include <cmath>

namespace robomill::toolpath {

double CutterShape::radius_at(double height_m) const noexcept {
  if (height_m < 0.0 || height_m > length_m)
    return 0.0;
  if (height_m >= corner_radius_m)
    return radius_m;
  // On the corner (the ball for corner radius R): a circle of the corner
  // radius centred at (R − r_c, r_c) in the (radius, height) plane.
  const double below_centre = corner_radius_m - height_m;
  return radius_m - corner_radius_m +
         std::sqrt(std::max(0.0, corner_radius_m * corner_radius_m - below_centre * below_centre));
}

CutterShape cutter_shape(const tool::Tool& tool) noexcept {
  CutterShape shape;
  shape.radius_m = tool.radius_m();
  shape.corner_radius_m = tool.corner_radius_m();
  shape.length_m = tool.overhang_m();
  return shape;
}

}  // namespace robomill::toolpath
