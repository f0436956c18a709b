#pragma once
// The atlas's SQLite result store (issue 11, docs/atlas.md). One file holds
// the job that made it (canonical text, its hash, the code version), every
// item with its inputs and status, and the results of finished items. The
// file is in WAL mode and opened with an exclusive lock, so a second run on
// the same store is refused while the first holds it; results are written in
// transactions, so a run killed at any moment loses only the uncommitted
// batch, and a re-run computes only the items without results.
//
// The store is not thread-safe: one thread (the run's main thread, or MPI
// rank 0) owns it; workers hand results back to it.

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "robomill/atlas/atlas.hpp"
#include "robomill/core/error.hpp"

struct sqlite3;

namespace robomill::atlas {

/// A store that cannot be used: not a database, not an atlas store, locked
/// by another process, an I/O failure. The message names the file.
class StoreError : public Error {
 public:
  using Error::Error;
};

/// A store written by another job or code version (refused unless restarted).
class StoreMismatch : public StoreError {
 public:
  using StoreError::StoreError;
};

/// 64-bit FNV-1a of `text`, as 16 hex digits.
std::string fnv1a_hex(std::string_view text);

/// The version of the atlas code whose results a store holds; a store from
/// another version is refused like one from another job.
inline constexpr std::string_view kAtlasCodeVersion = "robomill-0.1.0/atlas-1";

/// Identity of the job a store belongs to.
struct StoreIdentity {
  std::string job_text;  ///< canonical job text (the job file and its --set overrides)
  std::string job_hash;  ///< fnv1a_hex(job_text)
  std::string code_version{kAtlasCodeVersion};
  int dof = 0;
};

/// One finished item as read back.
struct StoredItem {
  AtlasItem item;
  AtlasResult result;
};

class AtlasStore {
 public:
  /// Opens (creating when absent) the store for `spec`'s items. A new or
  /// restarted store gets the job and all items (pending). An existing one
  /// must carry the same job hash and code version, else StoreMismatch
  /// (unless `restart`, which empties it first). Throws StoreError for a
  /// file that is not an atlas store or that another process holds.
  AtlasStore(const std::filesystem::path& file, const StoreIdentity& identity,
             const AtlasSpec& spec, bool restart);
  /// Opens an existing store read-only for export (same identity checks).
  AtlasStore(const std::filesystem::path& file, const StoreIdentity& identity);
  ~AtlasStore();
  AtlasStore(const AtlasStore&) = delete;
  AtlasStore& operator=(const AtlasStore&) = delete;

  std::int64_t item_total() const;
  /// Ids of items without results, ascending.
  std::vector<std::int64_t> pending() const;
  /// Writes finished items in one transaction (results + status).
  void commit(const std::vector<std::pair<std::int64_t, AtlasResult>>& batch);
  /// Every finished item with its inputs, by id.
  std::vector<StoredItem> finished() const;

  const std::filesystem::path& file() const noexcept { return file_; }
  int dof() const noexcept { return dof_; }

 private:
  void open(bool must_exist);
  void exec(const char* sql, const char* what);
  void check_identity(const StoreIdentity& identity, bool restart, const AtlasSpec* spec);
  [[noreturn]] void fail(const std::string& what, int code) const;

  std::filesystem::path file_;
  sqlite3* db_ = nullptr;
  int dof_ = 0;
};

}  // namespace robomill::atlas
