#include "robomill/io/output_bundle.hpp"

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <system_error>

#include "robomill/core/error.hpp"

namespace robomill::io {
namespace fs = std::filesystem;

OutputBundle::OutputBundle(fs::path directory) : directory_(std::move(directory)) {}

OutputBundle::~OutputBundle() {
  std::error_code ignored;
  for (const fs::path& temporary : temporaries_)
    fs::remove(temporary, ignored);
  for (const auto& [name, temporary] : adopted_)
    fs::remove(temporary, ignored);
}

void OutputBundle::adopt(const std::string& name, const fs::path& temporary) {
  if (name.empty() || name.find('/') != std::string::npos) {
    throw Error("output name must be a plain file name, got '" + name + "'");
  }
  adopted_.emplace_back(name, temporary);
}

fs::path OutputBundle::temporary_for(const std::string& name) const {
  std::error_code error;
  fs::create_directories(directory_, error);
  if (error) {
    throw Error("cannot create output folder " + directory_.string() + ": " + error.message());
  }
  return directory_ / ("." + name + ".stream-" + std::to_string(::getpid()));
}

void OutputBundle::add(const std::string& name, const std::string& content) {
  if (name.empty() || name.find('/') != std::string::npos) {
    throw Error("output name must be a plain file name, got '" + name + "'");
  }
  staged_.emplace_back(name, content);
}

std::vector<fs::path> OutputBundle::commit() {
  std::error_code error;
  fs::create_directories(directory_, error);
  if (error) {
    throw Error("cannot create output folder " + directory_.string() + ": " + error.message());
  }
  // Hidden temporaries in the same folder: rename(2) within one file system is
  // atomic, so readers see either the old file or the complete new one.
  const std::string suffix = ".tmp-" + std::to_string(::getpid());
  for (const auto& [name, content] : staged_) {
    const fs::path temporary = directory_ / ("." + name + suffix);
    temporaries_.push_back(temporary);
    std::ofstream stream(temporary, std::ios::binary | std::ios::trunc);
    stream.write(content.data(), static_cast<std::streamsize>(content.size()));
    stream.flush();
    if (!stream)
      throw Error("cannot write " + temporary.string());
  }
  std::vector<fs::path> written;
  for (std::size_t i = 0; i < staged_.size(); ++i) {
    const fs::path target = directory_ / staged_[i].first;
    fs::rename(temporaries_[i], target, error);
    if (error)
      throw Error("cannot rename into " + target.string() + ": " + error.message());
    written.push_back(target);
  }
  for (const auto& [name, temporary] : adopted_) {
    const fs::path target = directory_ / name;
    fs::rename(temporary, target, error);
    if (error)
      throw Error("cannot rename into " + target.string() + ": " + error.message());
    written.push_back(target);
  }
  adopted_.clear();
  temporaries_.clear();
  staged_.clear();
  return written;
}

void write_file_atomically(const fs::path& file, const std::string& content) {
  OutputBundle bundle(file.parent_path().empty() ? fs::path(".") : file.parent_path());
  bundle.add(file.filename().string(), content);
  bundle.commit();
}

}  // namespace robomill::io
