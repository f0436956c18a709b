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
#include <string>
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

/// The nominal job itself as draw 0 of a zero-spread run is NOT assumed:
/// callers compute the nominal job separately.

}  // namespace robomill::analysis
