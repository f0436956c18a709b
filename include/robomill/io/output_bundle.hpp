#pragma once
// All the files one command writes, committed together. Each file is written
// to a temporary name in the output folder and renamed into place only when
// every file of the bundle was written, so an interrupted or failing command
// leaves either nothing or complete results, never a truncated file.

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace robomill::io {

class OutputBundle {
 public:
  explicit OutputBundle(std::filesystem::path directory);
  ~OutputBundle();  // removes temporaries that were never committed
  OutputBundle(const OutputBundle&) = delete;
  OutputBundle& operator=(const OutputBundle&) = delete;

  /// Stages `content` as `name` (a plain file name inside the directory).
  void add(const std::string& name, const std::string& content);

  /// Takes over a file a long computation already streamed into the
  /// directory under a hidden temporary name (`samples.csv` of a whole
  /// program): commit renames it to `name` with the rest; a bundle that is
  /// never committed removes it.
  void adopt(const std::string& name, const std::filesystem::path& temporary);

  /// A hidden temporary name in the directory for a file to `adopt` later
  /// (creates the directory).
  std::filesystem::path temporary_for(const std::string& name) const;

  /// Creates the directory if needed, writes every staged file to a temporary
  /// name, flushes, then renames each into place. Throws robomill::Error with
  /// the path on any I/O failure, removing what it wrote.
  std::vector<std::filesystem::path> commit();

  /// The files staged so far (name, content), in the order they were added.
  const std::vector<std::pair<std::string, std::string>>& staged() const noexcept {
    return staged_;
  }
  std::filesystem::path directory() const { return directory_; }

 private:
  std::filesystem::path directory_;
  std::vector<std::pair<std::string, std::string>> staged_;
  std::vector<std::filesystem::path> temporaries_;
  std::vector<std::pair<std::string, std::filesystem::path>> adopted_;
};

/// One file, atomically (a bundle of one).
void write_file_atomically(const std::filesystem::path& file, const std::string& content);

}  // namespace robomill::io
