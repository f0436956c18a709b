// report.html: axis titles from column names, tables, no NaN, dispatch.

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

#include "../../src/report/detail.hpp"
#include "robomill/core/error.hpp"
#include "robomill/job/job.hpp"
#include "robomill/report/key_inputs.hpp"
#include "robomill/report/report.hpp"

namespace test_report_cpp {

namespace rr = robomill::report;
namespace rd = robomill::report::detail;

TEST(ReportAxes, TitlesCarryTheUnitsOfTheColumnNames) {
  EXPECT_EQ(rd::axis_title("spindle_rpm"), "spindle speed (rpm)");
  EXPECT_EQ(rd::axis_title("depth_limit_mm"), "limiting depth (mm)");
  EXPECT_EQ(rd::axis_title("chatter_freq_hz"), "chatter frequency (Hz)");
  EXPECT_EQ(rd::axis_title("t_s"), "time (s)");
  EXPECT_EQ(rd::axis_title("fx_N"), "Fx (N)");
  EXPECT_EQ(rd::axis_title("torque_Nm"), "torque (N·m)");
  EXPECT_EQ(rd::axis_title("k_N_per_m"), "modal stiffness k (N/m)");
  EXPECT_EQ(rd::axis_title("compliance_feed_um_per_N"), "compliance feed (µm/N)");
  EXPECT_EQ(rd::axis_title("mrr_cm3_per_min"), "material removal rate (cm³/min)");
  EXPECT_EQ(rd::axis_title("z_um"), "z (µm)");
  EXPECT_EQ(rd::axis_title("condition_number"), "condition number");
  EXPECT_EQ(rd::column_unit("bifurcation"), "");
}

TEST(ReportTables, ParsesNumbersAndTextAndFiltersRows) {
  const auto t = rd::Table::parse("frf,freq_hz,x\nxx,1,2\nyy,2,nan\nxx,3,\n");
  ASSERT_TRUE(t.has_value());
  EXPECT_EQ(t->rows(), 3u);
  EXPECT_EQ(t->distinct("frf"), (std::vector<std::string>{"xx", "yy"}));
  const rd::Table xx = t->where("frf", "xx");
  EXPECT_EQ(xx.rows(), 2u);
  EXPECT_DOUBLE_EQ(xx.numbers("freq_hz")[1], 3.0);
  EXPECT_TRUE(std::isnan(t->numbers("x")[2]));
  EXPECT_FALSE(rd::Table::parse("a,b\n1,2,3\n").has_value());
}

TEST(ReportValues, NonFiniteNumbersBecomeGapsAndValuesAreRounded) {
  const nlohmann::json v = rd::values({1.0 / 3.0, std::nan(""), INFINITY, -2.5});
  EXPECT_TRUE(v[1].is_null());
  EXPECT_TRUE(v[2].is_null());
  EXPECT_EQ(v[0].dump(), "0.333333");
  EXPECT_EQ(v.dump().find("NaN"), std::string::npos);
  EXPECT_EQ(rd::thin(10, 4).back(), 9u);
  EXPECT_LE(rd::thin(100000, 4000).size(), 4001u);
}

TEST(ReportPage, NeedsASummary) {
  EXPECT_THROW(rr::render_html({{"forces.csv", "t_s,fx_N\n0,1\n"}}), robomill::InputError);
  EXPECT_THROW(rr::render_html({{"summary.json", "[1, 2]"}}), robomill::InputError);
}

TEST(ReportPage, ForcesReportIsSelfContainedAndFinite) {
  const rr::Files files = {
      {"summary.json", R"({"command": "forces", "name": "demo", "mean_N": {"x": 1.5, "y": 2}})"},
      {"forces.csv",
       "angle_deg,t_s,fx_N,fy_N,fz_N,torque_Nm\n0,0,0,0,0,0\n1,0.001,nan,2,0,0.5\n"
       "2,0.002,3,1,0,0.25\n3,0.003,1,0,0,0.1\n4,0.004,0,0,0,0\n"
       "5,0.005,1,1,0,0.2\n6,0.006,2,1,0,0.3\n7,0.007,1,1,0,0.1\n"}};
  const std::string html = rr::render_html(files);
  EXPECT_NE(html.find("<script>"), std::string::npos);
  EXPECT_EQ(html.find("<script src="), std::string::npos);
  EXPECT_NE(html.find("force (N)"), std::string::npos);
  EXPECT_NE(html.find("mean_N.x"), std::string::npos);
  const std::size_t figures = html.find("id=\"robomill-figures\"");
  ASSERT_NE(figures, std::string::npos);
  EXPECT_EQ(html.find("NaN", figures), std::string::npos);
  EXPECT_GT(rr::plotly_js().size(), 1000000u);
  EXPECT_EQ(rr::plotly_js().find("</script"), std::string_view::npos);
}

TEST(ReportPage, UnknownCommandsGetGenericPlotsAndScriptTextIsEscaped) {
  const std::string html =
      rr::render_html({{"summary.json", R"({"command": "future", "name": "</script><b>x"})"},
                       {"data.csv", "a_mm,b_N\n0,1\n1,2\n2,3\n"}});
  EXPECT_EQ(html.find("</script><b>"), std::string::npos);
  EXPECT_NE(html.find("b (N)"), std::string::npos);
  EXPECT_FALSE(rr::has_dedicated_figures("future"));
  EXPECT_TRUE(rr::has_dedicated_figures("stability"));
}

TEST(ReportInputs, KeyInputsOfTheDemoJob) {
  const robomill::job::Job job =
      robomill::job::load_job(std::string(ROBOMILL_SOURCE_DIR) + "/examples/demo.yaml");
  const nlohmann::json inputs = nlohmann::json::parse(rr::key_inputs_json(job));
  ASSERT_TRUE(inputs["inputs"].is_array());
  bool ktc = false, spindle = false;
  for (const auto& row : inputs["inputs"]) {
    const std::string value = row["value"];
    ktc = ktc || value.find("855") != std::string::npos;
    spindle = spindle || (row["name"] == "spindle" && value.ends_with("rpm"));
  }
  EXPECT_TRUE(ktc);
  EXPECT_TRUE(spindle);
}

TEST(ReportInputs, RobotPathSettingsAndFeedLimitsOfTheRobotPocket) {
  const robomill::job::Job job = robomill::job::load_job(std::string(ROBOMILL_SOURCE_DIR) +
                                                         "/examples/toolpath_robot_pocket.yaml");
  const nlohmann::json inputs = nlohmann::json::parse(rr::key_inputs_json(job));
  std::map<std::string, std::string> robot_path;
  for (const auto& row : inputs["inputs"])
    if (row["group"] == "robot path")
      robot_path[row["name"]] = row["value"];
  EXPECT_EQ(robot_path["deflection"], "static");
  EXPECT_EQ(robot_path["feed limits"],
            "force 120 N, deflection 50 µm, joint speed 20 °/s; feed 50 – 2000 mm/min");
}

}  // namespace test_report_cpp
