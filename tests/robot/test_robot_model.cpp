// RobotModel: DH (standard and modified) and URDF chains, validation of the
// description, and the equivalence of the three descriptions of 004's robot.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "example_robots.hpp"
#include "robomill/robot/joint_dynamics.hpp"
#include "robomill/robot/kinematics.hpp"
#include "robomill/robot/robot_model.hpp"

namespace test_robot_model_cpp {

namespace {

using namespace robomill::robot;
using namespace robomill::test;

// The same robot in standard DH: frame i at the distal end of link i.
RobotDescription robot_004_standard() {
  RobotDescription d = robot_004();
  DhTable dh;
  dh.convention = DhConvention::standard;
  dh.rows = {{0.0, kPi / 2, 0.2, 0.0}, {0.8, 0.0, 0.0, 0.0}, {0.8, 0.0, 0.0, 0.0}};
  // Standard frame 1: origin at o2, y1 up, z1 = −y: the c.o.m. 0.1 m below.
  dh.links = {link(80, {0, -0.1, 0}, {0.9, 1.0, 1.0}), link(40, {-0.4, 0, 0}, {0.6, 6.5, 6.5}),
              link(55, {-0.4, 0, 0}, {0.8, 9.5, 9.5})};
  d.dh = dh;
  d.flange_to_tool = Eigen::Isometry3d::Identity();
  return d;
}

const char* kUrdf004 = R"(<?xml version="1.0"?>
<robot name="r004">
  <link name="base"/>
  <link name="link1">
    <inertial><origin xyz="0 0 0.1"/><mass value="80"/>
      <inertia ixx="0.9" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="link2">
    <inertial><origin xyz="0.4 0 0"/><mass value="40"/>
      <inertia ixx="0.6" iyy="6.5" izz="6.5" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="link3">
    <inertial><origin xyz="0.4 0 0"/><mass value="55"/>
      <inertia ixx="0.8" iyy="9.5" izz="9.5" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="flange"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="link1"/>
    <origin xyz="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3.0" upper="3.0" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="link1"/><child link="link2"/>
    <origin xyz="0 0 0.2" rpy="1.5707963267948966 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1.5" upper="1.5" effort="1" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="link2"/><child link="link3"/>
    <origin xyz="0.8 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1.0" upper="1.0" effort="1" velocity="1"/></joint>
  <joint name="jf" type="fixed"><parent link="link3"/><child link="flange"/>
    <origin xyz="0.8 0 0"/></joint>
</robot>)";

RobotDescription robot_004_urdf() {
  RobotDescription d;
  d.name = "004-urdf";
  d.urdf = UrdfSource{kUrdf004, "base", "flange"};
  d.joints = joints_004();
  d.modal_damping_ratio = 0.06;
  return d;
}

void expect_invalid(const RobotDescription& d, const std::string& fragment) {
  try {
    RobotModel m(d);
    FAIL() << "expected std::invalid_argument containing '" << fragment << "'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos)
        << "message: " << e.what() << "\nexpected to contain: " << fragment;
  }
}

TEST(RobotModel, BuildsDhChainWithToolSegment) {
  const RobotModel m(robot_004());
  EXPECT_EQ(m.dof(), 3);
  EXPECT_EQ(m.chain().getNrOfJoints(), 3u);
  EXPECT_EQ(m.chain().getNrOfSegments(), 4u);  // three links + the fixed tool segment
  EXPECT_EQ(m.chain().getSegment(3).getName(), "tool");
  EXPECT_EQ(m.joint_stiffness(), Eigen::Vector3d(2.4e5, 1e5, 1e5));
  EXPECT_TRUE(m.within_limits(Eigen::Vector3d(0.0, 1.5, -1.0)));
  EXPECT_FALSE(m.within_limits(Eigen::Vector3d(0.0, 1.6, 0.0)));
  EXPECT_FALSE(m.within_limits(Eigen::Vector3d(0.0, 1.5, 0.0), 0.1));
  EXPECT_FALSE(m.within_limits(Eigen::Vector2d(0.0, 0.0)));
}

TEST(RobotModel, ModifiedDhPlacesThe004RobotAsSection41Says) {
  // q = 0: links 2 and 3 stretched along x at the height l1 = 0.2 m; q2 > 0
  // lifts the arm (z2 = −y), q1 turns it about the vertical.
  const RobotModel m(robot_004());
  EXPECT_LT(
      (tool_pose(m, Eigen::Vector3d::Zero()).translation() - Eigen::Vector3d(1.6, 0, 0.2)).norm(),
      1e-15);
  const Eigen::Vector3d p = tool_pose(m, Eigen::Vector3d(kPi / 2, kPi / 6, 0.0)).translation();
  const double r = 1.6 * std::cos(kPi / 6);
  EXPECT_LT((p - Eigen::Vector3d(0.0, r, 0.2 + 1.6 * std::sin(kPi / 6))).norm(), 1e-14);
}

TEST(RobotModel, StandardModifiedAndUrdfDescriptionsOf004Agree) {
  // The same robot three ways: tool poses and mass matrices must coincide,
  // which checks the placement of the joint axes and the link inertias in
  // each convention (KDL: segment inertia in the segment's tip frame).
  const RobotModel mod(robot_004());
  const RobotModel std_dh(robot_004_standard());
  const RobotModel urdf(robot_004_urdf());
  for (const Eigen::Vector3d& q : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.3, -0.7, 0.9),
                                   Eigen::Vector3d(-2, 1.2, -0.4)}) {
    const Eigen::Isometry3d a = tool_pose(mod, q);
    EXPECT_LT((tool_pose(std_dh, q).translation() - a.translation()).norm(), 1e-14);
    EXPECT_LT((tool_pose(urdf, q).translation() - a.translation()).norm(), 1e-14);
    // Orientation differs only by the fixed tool frames: compare x (link 3).
    EXPECT_LT((tool_pose(urdf, q).linear() - a.linear()).norm(), 1e-14);
    const Eigen::MatrixXd m_mod = mass_matrix(mod, q);
    EXPECT_LT((mass_matrix(std_dh, q) - m_mod).norm(), 1e-12 * m_mod.norm());
    EXPECT_LT((mass_matrix(urdf, q) - m_mod).norm(), 1e-12 * m_mod.norm());
  }
}

TEST(RobotModel, UrdfLimitsAreTakenFromTheFileWhenAsked) {
  const RobotModel with(robot_004_urdf());
  EXPECT_DOUBLE_EQ(with.joints()[0].lower_rad, -3.0);
  EXPECT_DOUBLE_EQ(with.joints()[2].upper_rad, 1.0);
  RobotDescription d = robot_004_urdf();
  d.use_urdf_limits = false;
  const RobotModel without(d);
  EXPECT_DOUBLE_EQ(without.joints()[2].upper_rad, kPi / 3);
}

TEST(RobotModel, BaseAndToolFramesAreApplied) {
  RobotDescription d = robot_004();
  d.base =
      Eigen::Translation3d(1.0, 2.0, 0.5) * Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ());
  d.flange_to_tool =
      Eigen::Translation3d(0.8, 0.0, 0.1) * Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitY());
  const RobotModel m(d);
  const Eigen::Isometry3d t = tool_pose(m, Eigen::Vector3d::Zero());
  // Flange at (0.8, 0, 0.2) in the base, tool 0.8 further along x3 = x and
  // 0.1 along z3 = −y; the base turns x into y and shifts by (1, 2, 0.5).
  EXPECT_LT((t.translation() - Eigen::Vector3d(1.0 + 0.1, 2.0 + 1.6, 0.7)).norm(), 1e-14);
}

TEST(RobotModelValidation, RejectsBadJointsNamingThem) {
  RobotDescription d = robot_004();
  d.joints[1].stiffness_nm_per_rad = 0.0;
  expect_invalid(d, "joint 2");
  d = robot_004();
  d.joints[2].stiffness_nm_per_rad = std::nan("");
  expect_invalid(d, "joint 3: stiffness");
  d = robot_004();
  d.joints[0].lower_rad = 1.0;
  d.joints[0].upper_rad = 1.0;
  expect_invalid(d, "joint 1: lower limit");
  d = robot_004();
  d.joints[2].damping_nms_per_rad = -3.0;
  expect_invalid(d, "joint 3: damping");
  d = robot_004();
  d.joints.pop_back();
  expect_invalid(d, "3 rows but 2 joint entries");
  d = robot_004();
  d.joints.clear();
  expect_invalid(d, "no joints");
  d = robot_004();
  d.urdf = UrdfSource{kUrdf004, "base", "flange"};
  expect_invalid(d, "exactly one of");
  d = robot_004();
  d.modal_damping_ratio = 1.5;
  expect_invalid(d, "modal_damping_ratio");
}

TEST(RobotModelValidation, RejectsBadLinksNamingThem) {
  RobotDescription d = robot_004();
  d.dh->links[1].mass_kg = -1.0;
  expect_invalid(d, "link 2: mass");
  d = robot_004();
  d.dh->links[2].inertia_kg_m2(0, 0) = -0.5;  // not PSD
  expect_invalid(d, "link 3: inertia tensor must be positive semi-definite");
  d = robot_004();
  d.dh->links[0].inertia_kg_m2(0, 1) = 0.3;  // not symmetric
  expect_invalid(d, "link 1: inertia tensor must be symmetric");
  d = robot_004();
  d.dh->links.pop_back();
  expect_invalid(d, "2 links");
}

TEST(RobotModelValidation, RejectsBadUrdf) {
  RobotDescription d = robot_004_urdf();
  d.urdf->xml = "<robot name='x'><link name='a'/><joint name='j' type='revolute'>";
  expect_invalid(d, "does not parse");
  d = robot_004_urdf();
  d.urdf->tip_link = "no_such_link";
  expect_invalid(d, "no chain from base_link 'base' to tip_link 'no_such_link'");
  d = robot_004_urdf();
  d.joints.pop_back();
  expect_invalid(d, "has 3 revolute joints but 2 joint entries");
  d = robot_004_urdf();
  std::string xml = kUrdf004;
  xml.replace(xml.find("name=\"j2\" type=\"revolute\""), 25, "name=\"j2\" type=\"prismatic\"");
  d.urdf->xml = xml;
  expect_invalid(d, "joint 'j2' (joint 2) is not revolute");
  d = robot_004_urdf();
  xml = kUrdf004;
  xml.replace(xml.find("<mass value=\"40\"/>"), 18, "<mass value=\"-4\"/>");
  d.urdf->xml = xml;
  // urdfdom may already refuse a negative mass; either way it is rejected.
  EXPECT_THROW(RobotModel{d}, std::invalid_argument);
}

}  // namespace

}  // namespace test_robot_model_cpp
