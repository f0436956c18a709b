#pragma once
// Private to the commands: what `robomill toolpath` writes about the draws
// of the uncertain inputs (issue 33) and about --optimize's better program
// (analysis/program_improvement.hpp): summary.json's parts, the files and
// the console lines (toolpath_outputs.cpp).

#include <nlohmann/json.hpp>
#include <string>

#include "robomill/analysis/job_draws.hpp"
#include "robomill/analysis/program_improvement.hpp"
#include "robomill/analysis/robot_path_setup.hpp"
#include "robomill/commands/command_result.hpp"

namespace robomill::commands::detail {

/// summary.json's robot_along_path.uncertainty (and optimization.after's):
/// the draws, the expected number of chattering samples, the most probable
/// chatter and the lines over the bound.
nlohmann::json path_uncertainty_json(const analysis::JobDraws& draws,
                                     double max_chatter_probability,
                                     const robot_path::RobotPathSummary& r);
/// The console's line on the same.
std::string path_uncertainty_message(double max_chatter_probability,
                                     const robot_path::RobotPathSummary& r);

/// summary.json's `optimization`; `draws` is null without uncertainty.
nlohmann::json improvement_json(const analysis::ProgramImprovement& im,
                                const analysis::RobotPathSetup& setup,
                                const analysis::JobDraws* draws);
/// The improvement's files: redundancy_schedule.csv when ψ changes per line,
/// the written program (and its .dat) when the program changed.
void add_improvement_files(const analysis::ProgramImprovement& im, CommandResult& result);
/// The message's optimize lines.
std::string improvement_message(const analysis::ProgramImprovement& im,
                                const analysis::RobotPathSetup& setup,
                                const analysis::JobDraws* draws);

}  // namespace robomill::commands::detail
