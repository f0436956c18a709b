#pragma once
// Private to the job parser: the `learn:` section of `robomill learn`
// (issue 35, docs/learning.md).

#include "robomill/job/job.hpp"
#include "yaml_reader.hpp"

namespace robomill::job::detail {

/// Reads `experiments` (cutting tests and hammer tests, the evidence of
/// `robomill learn` and the tests `stability` compares with). Throws
/// InputError naming the entry's field and line.
std::vector<Experiment> read_experiments(SectionReader& root, const Job& job);

/// Reads `learn` into job.learn (after `uncertainty`, whose seed is its
/// default seed). Throws InputError naming the field and line.
void read_learn(SectionReader& root, Job& job);

}  // namespace robomill::job::detail
