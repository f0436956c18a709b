// The `robot:` section of a job: DH table or URDF, joint stiffness, link
// inertias, posture, tool frame (000 §2, 002 §2).

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "job_parser_robot.hpp"
#include "quantity_fields.hpp"
#include "robomill/core/error.hpp"
#include "robomill/job/job.hpp"

namespace robomill::job::detail {

namespace {

/// `{xyz: [x, y, z], rpy: [roll, pitch, yaw]}` (mm and deg by default): a
/// frame as a translation and fixed-axis X-Y-Z rotations (URDF's convention).
Eigen::Isometry3d read_frame(SectionReader& f, std::string_view schema_section) {
  f.allow_schema(schema_section);
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  if (auto xyz = f.quantities("xyz", length_mm({}), 3))
    frame.translation() = Eigen::Vector3d((*xyz)[0], (*xyz)[1], (*xyz)[2]);
  if (auto rpy = f.quantities("rpy", field(dimensions::angle, kDeg, "deg"), 3)) {
    frame.linear() = (Eigen::AngleAxisd((*rpy)[2], Eigen::Vector3d::UnitZ()) *
                      Eigen::AngleAxisd((*rpy)[1], Eigen::Vector3d::UnitY()) *
                      Eigen::AngleAxisd((*rpy)[0], Eigen::Vector3d::UnitX()))
                         .toRotationMatrix();
  }
  f.finish();
  return frame;
}

/// `dh:` (with its `convention`), the DH table, one row per joint.
void read_dh_table(SectionReader& r, robot::RobotDescription& d, const QuantityField& angle) {
  if (r.has("dh")) {
    // DESIGN.md: `dh` is a list of {a, alpha, d, theta} rows, theta the joint
    // offset; `convention` says which DH.
    robot::DhTable table;
    table.convention = r.choice("convention", {"standard", "modified"}, "standard") == "modified"
                           ? robot::DhConvention::modified
                           : robot::DhConvention::standard;
    auto rows = r.sections("dh");
    if (rows->empty())
      r.fail("dh", "required: one row {a, alpha, d, theta} per joint");
    for (SectionReader& row : *rows) {
      row.allow_schema("robot.dh[]");
      robot::DhRow entry;
      entry.a_m = row.quantity_or("a", length_mm({}), 0.0);
      entry.alpha_rad = row.quantity_or("alpha", angle, 0.0);
      entry.d_m = row.quantity_or("d", length_mm({}), 0.0);
      entry.theta_offset_rad = row.quantity_or("theta", angle, 0.0);
      row.finish();
      table.rows.push_back(entry);
    }
    d.dh = std::move(table);
  } else if (r.has("convention")) {
    r.fail("convention", "applies to a DH table (dh:), not to a URDF file");
  }
}

/// `urdf:` {file, base, tip, limits_from_file}: the URDF file read whole.
void read_urdf(SectionReader& r, const std::filesystem::path& source, RobotSettings& settings) {
  robot::RobotDescription& d = settings.description;
  if (auto urdf = r.section("urdf")) {
    urdf->allow_schema("robot.urdf");
    const auto file = urdf->optional_text("file");
    if (!file || file->empty())
      urdf->fail("file", "required field missing (path of the URDF file, relative to the job)");
    settings.urdf_file = source.empty() ? std::filesystem::path(*file)
                                        : source.parent_path() / std::filesystem::path(*file);
    robot::UrdfSource urdf_source;
    urdf_source.base_link = urdf->optional_text("base").value_or("");
    urdf_source.tip_link = urdf->optional_text("tip").value_or("");
    if (urdf_source.base_link.empty())
      urdf->fail("base", "required field missing (the chain's root link)");
    if (urdf_source.tip_link.empty())
      urdf->fail("tip", "required field missing (the flange link)");
    d.use_urdf_limits = urdf->boolean_or("limits_from_file", true);
    // Only regular files of sane size: a path such as /dev/zero must not hang
    // the parser (URDF files are kilobytes to a few megabytes).
    std::error_code error;
    const bool regular = std::filesystem::is_regular_file(settings.urdf_file, error);
    const auto bytes = regular ? std::filesystem::file_size(settings.urdf_file, error) : 0;
    if (!regular || error)
      urdf->fail("file", "cannot read '" + settings.urdf_file.string() + "' (not a regular file)");
    if (bytes > 64u * 1024u * 1024u)
      urdf->fail("file", "'" + settings.urdf_file.string() + "' is larger than 64 MiB");
    std::ifstream in(settings.urdf_file, std::ios::binary);
    if (!in)
      urdf->fail("file", "cannot read '" + settings.urdf_file.string() + "'");
    urdf_source.xml.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    urdf->finish();
    d.urdf = std::move(urdf_source);
  }
}

/// `joint_stiffness` and `joints:` (limits, damping), one per joint.
void read_joints(SectionReader& r, robot::RobotDescription& d, const QuantityField& angle) {
  // DESIGN.md: `joint_stiffness`, one value per joint (000 §6.1's Kq).
  const auto stiffness = r.quantities(
      "joint_stiffness", field(dimensions::rotational_stiffness, 1.0, "N*m/rad", kPositive));
  if (!stiffness)
    r.fail("joint_stiffness", "required: the torsional stiffness of every joint, N*m/rad");
  if (d.dh && stiffness->size() != d.dh->rows.size()) {
    r.fail("joint_stiffness",
           fmt::format("lists {} values but dh has {} rows", stiffness->size(), d.dh->rows.size()));
  }
  for (const double k : *stiffness) {
    robot::JointProperties joint;
    joint.stiffness_nm_per_rad = k;
    joint.damping_nms_per_rad = robot::kDeriveDamping;
    d.joints.push_back(joint);
  }
  if (auto joints = r.sections("joints")) {
    if (joints->size() != d.joints.size()) {
      r.fail("joints", fmt::format("lists {} joints; one per joint ({}) needed", joints->size(),
                                   d.joints.size()));
    }
    for (std::size_t i = 0; i < joints->size(); ++i) {
      SectionReader& j = (*joints)[i];
      j.allow_schema("robot.joints[]");
      robot::JointProperties& joint = d.joints[i];
      joint.lower_rad = j.quantity_or("lower", angle, joint.lower_rad);
      joint.upper_rad = j.quantity_or("upper", angle, joint.upper_rad);
      if (!(joint.upper_rad > joint.lower_rad))
        j.fail("upper", "must exceed lower");
      joint.damping_nms_per_rad = j.quantity_or(
          "damping", field(dimensions::rotational_damping, 1.0, "N*m*s/rad", kNonNegative),
          robot::kDeriveDamping);
      j.finish();
    }
  }
}

/// `links:`, the inertia of each link of a DH table.
void read_links(SectionReader& r, robot::RobotDescription& d) {
  if (auto links = r.sections("links")) {
    if (!d.dh)
      r.fail("links", "are read from the URDF file; give links only with a DH table");
    if (links->size() != d.joints.size())
      r.fail("links", fmt::format("lists {} links; one per joint ({}) needed", links->size(),
                                  d.joints.size()));
    for (SectionReader& l : *links) {
      l.allow_schema("robot.links[]");
      robot::LinkInertia link;
      link.mass_kg = l.quantity("mass", field(dimensions::mass, 1.0, "kg", kNonNegative));
      if (auto cog = l.quantities("cog", length_mm({}), 3))
        link.center_of_mass_m = Eigen::Vector3d((*cog)[0], (*cog)[1], (*cog)[2]);
      if (auto inertia =
              l.quantities("inertia", field(dimensions::moment_of_inertia, 1.0, "kg*m^2"))) {
        // [Ixx, Iyy, Izz] (principal axes along the link frame) or
        // [Ixx, Iyy, Izz, Ixy, Ixz, Iyz], about the centre of mass.
        const auto& v = *inertia;
        if (v.size() != 3 && v.size() != 6)
          l.fail("inertia", "expected [Ixx, Iyy, Izz] or [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] in kg*m^2");
        link.inertia_kg_m2.diagonal() << v[0], v[1], v[2];
        if (v.size() == 6) {
          link.inertia_kg_m2(0, 1) = link.inertia_kg_m2(1, 0) = v[3];
          link.inertia_kg_m2(0, 2) = link.inertia_kg_m2(2, 0) = v[4];
          link.inertia_kg_m2(1, 2) = link.inertia_kg_m2(2, 1) = v[5];
        }
      }
      l.finish();
      d.dh->links.push_back(link);
    }
  }
}

/// `frf:` {from, to, points}: the tool-tip FRF's frequency range.
void read_robot_frf(SectionReader& r, RobotSettings& settings) {
  if (auto frf = r.section("frf")) {
    frf->allow_schema("robot.frf");
    settings.frf_from_hz =
        frf->quantity_or("from", field(dimensions::frequency, 1.0, "Hz", kPositive), 0.0);
    settings.frf_to_hz =
        frf->quantity_or("to", field(dimensions::frequency, 1.0, "Hz", kPositive), 0.0);
    if (settings.frf_from_hz > 0.0 && settings.frf_to_hz > 0.0 &&
        !(settings.frf_to_hz > settings.frf_from_hz))
      frf->fail("to", "must exceed from");
    settings.frf_points = frf->integer_or("points", 2, 1000000, settings.frf_points);
    frf->finish();
  }
}

/// `map:` {from, to, counts, tool_axis, feed, redundancy}: a workspace map's grid.
void read_robot_map(SectionReader& r, RobotSettings& settings) {
  if (auto map = r.section("map")) {
    map->allow_schema("robot.map");
    RobotSettings::Map grid;
    const auto from = map->quantities("from", length_mm({}), 3);
    const auto to = map->quantities("to", length_mm({}), 3);
    if (!from)
      map->fail("from", "required: the grid's first corner [x, y, z] in the cell frame");
    if (!to)
      map->fail("to", "required: the grid's opposite corner [x, y, z]");
    grid.from_m = Eigen::Vector3d((*from)[0], (*from)[1], (*from)[2]);
    grid.to_m = Eigen::Vector3d((*to)[0], (*to)[1], (*to)[2]);
    // [nx, ny, nz] point counts.
    if (auto counts = map->integers("counts", 3, 1, 1000))
      std::copy(counts->begin(), counts->end(), grid.counts.begin());
    if (static_cast<long>(grid.counts[0]) * grid.counts[1] * grid.counts[2] > 1000000)
      map->fail("counts", "more than 1 000 000 grid points");
    grid.tool_axis = map->unit_vector_or("tool_axis", grid.tool_axis);
    grid.feed = map->unit_vector_or("feed", grid.feed);
    // The feed lies in the cutting plane: remove its component along the tool axis.
    grid.feed -= grid.feed.dot(grid.tool_axis) * grid.tool_axis;
    if (!(grid.feed.norm() > 1e-9))
      map->fail("feed", "must not be parallel to tool_axis");
    grid.feed.normalize();
    grid.redundancy_rad =
        map->quantity_or("redundancy", field(dimensions::angle, kDeg, "deg"), 0.0);
    map->finish();
    settings.map = grid;
  }
}

}  // namespace

RobotSettings read_robot_section(SectionReader& r, const std::filesystem::path& source) {
  r.allow_schema("robot");
  RobotSettings settings;
  robot::RobotDescription& d = settings.description;
  d.name = r.optional_text("name").value_or("robot");
  if (r.has("dh") == r.has("urdf"))
    r.fail_here("give the geometry either as a DH table (dh:) or as a URDF file (urdf:)");
  const QuantityField angle = field(dimensions::angle, kDeg, "deg");
  read_dh_table(r, d, angle);
  read_urdf(r, source, settings);
  read_joints(r, d, angle);
  read_links(r, d);
  d.modal_damping_ratio =
      r.quantity_or("damping_ratio", dimensionless(kNonNegative, Bound{1.0, false}), 0.0);
  if (auto base = r.section("base"))
    d.base = read_frame(*base, "robot.base");
  if (auto tool = r.section("tool"))
    d.flange_to_tool = read_frame(*tool, "robot.tool");
  if (auto posture =
          r.quantities("posture", field(dimensions::angle, kDeg, "deg"), d.joints.size()))
    settings.posture_rad = *posture;
  read_robot_frf(r, settings);
  read_robot_map(r, settings);
  r.finish();
  return settings;
}

}  // namespace robomill::job::detail
