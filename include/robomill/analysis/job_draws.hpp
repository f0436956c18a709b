#pragma once
// The uncertain inputs of a job, drawn, and the job of each draw (issue 33;
// docs/uncertainty.md, "From a job").
//
// draw_job_inputs turns the job's `uncertainty:` section into a samples ×
// variables matrix: uncertainty::draw() over the variables' distributions
// (their parameters resolved to SI, or to factors, when the job was read),
// with the section's samples, seed, point set and correlation; or the rows of
// its posterior file. job_of_draw then reads the job again with one more
// `--set` per field a variable sets, the drawn number written with 17
// significant digits in the SI unit of the field's dimension (read back
// exactly), so a drawn job is validated exactly as a job file is: a draw the
// job refuses (a negative stiffness from a wide normal) is an InputError
// naming the variable and the draw.

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "robomill/job/job.hpp"

namespace robomill::analysis {

/// The uncertain inputs of a job drawn (its uncertainty: section).
struct JobDraws {
  std::vector<std::string> names;  ///< the variables, in the job's order
  /// samples x variables: a value variable's drawn value in SI, a scale
  /// variable's factor.
  Eigen::MatrixXd values;
  std::string source;  ///< "sobol", "random" or the posterior file's path
};

/// The draws of the job's uncertainty: section (or its posterior file).
/// Throws InputError naming uncertainty.* fields and lines.
JobDraws draw_job_inputs(const job::Job& job);

/// The job with draw `i` applied: every variable's paths set to its value
/// (or the nominal value times its factor), then validated as any job.
/// A draw the job refuses (a negative stiffness) throws InputError naming
/// the variable, the draw, the value and the job's own message. Thread-safe.
/// The drawn job has no uncertainty: section (it is one point of the
/// uncertain job). Throws std::invalid_argument when `draws` is not the
/// job's (other variables) or `i` is not a row of it, and when the job has
/// no uncertainty: section or was not read from text (Job::yaml_text).
job::Job job_of_draw(const job::Job& nominal, const JobDraws& draws, std::size_t i);

/// Whether every variable of the job's uncertainty: section sets cutting
/// coefficients or structure (a field under `cutting.`, `dynamics.` or
/// `robot.`): then every draw cuts with the nominal tool, process and
/// engagement, and what depends on the cut's geometry alone (the A0 basis of
/// the zero-order method) is the same for all draws.
bool draws_keep_the_cut(const job::Job& job);

/// For analyses that keep the nominal postures and cut for every draw (the
/// robot along a program: `what` names it): throws InputError naming the
/// first variable whose path sets anything but cutting coefficients,
/// stability settings, modes or the robot's stiffness, damping and masses
/// (its kinematics, the placement, the tool and the program would move the
/// postures or the engagement).
void require_draws_keep_the_postures(const job::Job& job, std::string_view what);

/// Runs `body(i)` for every draw i on up to `threads` threads (0: all
/// cores), for analyses that compute something per draw and write it to
/// their own row. An InputError or NumericalError a draw throws is rethrown
/// with the draw named and its values ("uncertainty draw 3 of 64 (k_x =
/// -1.2e+06): ..."), keeping an InputError's field and line. A failing draw
/// stops the draws after it; the ones before it still run, so the error
/// rethrown is the first failing draw's whatever the thread count.
void for_each_draw(const JobDraws& draws, int threads,
                   const std::function<void(std::size_t)>& body);

/// The nominal job itself as draw 0 of a zero-spread run is NOT assumed:
/// callers compute the nominal job separately.

}  // namespace robomill::analysis
