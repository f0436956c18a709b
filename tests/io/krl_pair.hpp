#pragma once
// A KRL program's .src and .dat written to a scratch folder and read back
// through the KRL reader (tests/io: the frame turns and the moved points).

#include <filesystem>
#include <fstream>
#include <string>

#include "robomill/analysis/program_file.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/job/job.hpp"

namespace robomill::io::testing {

inline toolpath::Program read_krl_pair(const job::ToolpathSettings& settings,
                                       const std::string& src, const std::string& dat,
                                       const std::string& folder_name) {
  const std::filesystem::path folder = std::filesystem::temp_directory_path() / folder_name;
  std::filesystem::create_directories(folder);
  job::ToolpathSettings again = settings;
  again.file = folder / "written.src";
  again.dat_file = folder / "written.dat";
  std::ofstream(again.file, std::ios::binary) << src;
  std::ofstream(again.dat_file, std::ios::binary) << dat;
  toolpath::Program program = analysis::read_program(again);
  std::filesystem::remove_all(folder);
  return program;
}

}  // namespace robomill::io::testing
