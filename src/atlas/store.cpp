// The atlas's SQLite result store (include/robomill/atlas/store.hpp).

#include "robomill/atlas/store.hpp"

#include <sqlite3.h>

#include <cstdio>
#include <cstring>

namespace robomill::atlas {
namespace {

constexpr const char* kSchema = R"sql(
CREATE TABLE job(
  id INTEGER PRIMARY KEY CHECK (id = 1),
  job_text TEXT NOT NULL,
  job_hash TEXT NOT NULL,
  code_version TEXT NOT NULL,
  dof INTEGER NOT NULL,
  items INTEGER NOT NULL);
CREATE TABLE items(
  id INTEGER PRIMARY KEY,
  x_m REAL NOT NULL, y_m REAL NOT NULL, z_m REAL NOT NULL,
  redundancy_rad REAL NOT NULL,
  status INTEGER NOT NULL DEFAULT 0);
CREATE TABLE results(
  item_id INTEGER PRIMARY KEY REFERENCES items(id),
  reachable INTEGER NOT NULL,
  lowest_fn_hz REAL NOT NULL,
  compliance_feed_m_per_n REAL NOT NULL,
  compliance_normal_m_per_n REAL NOT NULL,
  compliance_axial_m_per_n REAL NOT NULL,
  condition_number REAL NOT NULL,
  depth_min_m REAL NOT NULL, speed_at_min_rad_s REAL NOT NULL,
  depth_max_m REAL NOT NULL, speed_at_max_rad_s REAL NOT NULL,
  q_rad BLOB);
)sql";

/// A prepared statement, finalized on scope exit.
class Statement {
 public:
  Statement(sqlite3* db, const char* sql) {
    code_ = sqlite3_prepare_v2(db, sql, -1, &statement_, nullptr);
  }
  ~Statement() { sqlite3_finalize(statement_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  int prepared() const { return code_; }
  sqlite3_stmt* get() const { return statement_; }

 private:
  sqlite3_stmt* statement_ = nullptr;
  int code_ = SQLITE_OK;
};

}  // namespace

std::string fnv1a_hex(std::string_view text) {
  std::uint64_t hash = 14695981039346656037ULL;
  for (const unsigned char c : text) {
    hash ^= c;
    hash *= 1099511628211ULL;
  }
  char buffer[17];
  std::snprintf(buffer, sizeof buffer, "%016llx", static_cast<unsigned long long>(hash));
  return buffer;
}

void AtlasStore::fail(const std::string& what, int code) const {
  const std::string path = file_.string();
  const int primary = code & 0xff;
  if (primary == SQLITE_NOTADB || primary == SQLITE_CORRUPT) {
    throw StoreError("atlas store " + path + ": " + what +
                     ": not a readable SQLite database (corrupt, or another kind of file); "
                     "move it away or name another atlas.store");
  }
  if (primary == SQLITE_BUSY || primary == SQLITE_LOCKED) {
    throw StoreError("atlas store " + path + ": " + what +
                     ": locked by another process (a robomill atlas still running on it?)");
  }
  const char* message = db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(code);
  throw StoreError("atlas store " + path + ": " + what + ": " + message);
}

void AtlasStore::exec(const char* sql, const char* what) {
  char* message = nullptr;
  const int code = sqlite3_exec(db_, sql, nullptr, nullptr, &message);
  sqlite3_free(message);
  if (code != SQLITE_OK)
    fail(what, code);
}

void AtlasStore::open(bool must_exist) {
  if (must_exist && !std::filesystem::exists(file_))
    throw StoreError("atlas store " + file_.string() +
                     ": no such file (run robomill atlas on the job first)");
  const int flags = SQLITE_OPEN_READWRITE | (must_exist ? 0 : SQLITE_OPEN_CREATE);
  const int code = sqlite3_open_v2(file_.string().c_str(), &db_, flags, nullptr);
  if (code != SQLITE_OK)
    fail("cannot open", code);
  sqlite3_busy_timeout(db_, 200);
  // Exclusive locking before WAL: the WAL index lives in this process's
  // memory and no other connection can read or write while this one is open.
  exec("PRAGMA locking_mode=EXCLUSIVE", "cannot lock");
  exec("PRAGMA journal_mode=WAL", "cannot switch to WAL");
  exec("PRAGMA synchronous=NORMAL", "cannot set synchronous");
  // Take the lock now (a write transaction), so that a second run fails here.
  exec("BEGIN IMMEDIATE", "cannot lock");
  exec("COMMIT", "cannot lock");
}

void AtlasStore::check_identity(const StoreIdentity& identity, bool restart,
                                const AtlasSpec* spec) {
  int tables = 0, job_table = 0;
  {
    Statement s(db_, "SELECT count(*), sum(name = 'job') FROM sqlite_master WHERE type = 'table'");
    if (s.prepared() != SQLITE_OK)
      fail("cannot read", s.prepared());
    const int code = sqlite3_step(s.get());
    if (code != SQLITE_ROW)
      fail("cannot read", code);
    tables = sqlite3_column_int(s.get(), 0);
    job_table = sqlite3_column_int(s.get(), 1);
  }
  if (tables > 0 && job_table == 0)
    throw StoreError("atlas store " + file_.string() +
                     ": an SQLite database but not a robomill atlas store (no job table)");
  bool create = tables == 0;
  if (!create) {
    std::string hash, version;
    {
      Statement s(db_, "SELECT job_hash, code_version, dof FROM job WHERE id = 1");
      if (s.prepared() != SQLITE_OK)
        fail("cannot read the job table", s.prepared());
      if (sqlite3_step(s.get()) != SQLITE_ROW)
        throw StoreError("atlas store " + file_.string() + ": the job table is empty");
      hash = reinterpret_cast<const char*>(sqlite3_column_text(s.get(), 0));
      version = reinterpret_cast<const char*>(sqlite3_column_text(s.get(), 1));
      dof_ = sqlite3_column_int(s.get(), 2);
    }
    if (hash != identity.job_hash || version != identity.code_version) {
      if (!restart || !spec) {
        throw StoreMismatch(
            "atlas store " + file_.string() + " was written by " +
            (hash != identity.job_hash
                 ? "another job (hash " + hash + ", this job " + identity.job_hash + ")"
                 : "another robomill version (" + version + ", this " + identity.code_version +
                       ")") +
            (spec ? "; use --restart to discard it and start over, or name another atlas.store"
                  : ""));
      }
    }
    if (restart && spec) {
      exec(
          "BEGIN; DROP TABLE IF EXISTS results; DROP TABLE IF EXISTS items; "
          "DROP TABLE IF EXISTS job; COMMIT",
          "cannot empty the store");
      create = true;
    }
  } else if (!spec) {
    throw StoreError("atlas store " + file_.string() + ": empty (no job)");
  }
  if (!create)
    return;
  dof_ = identity.dof;
  exec("BEGIN", "cannot write");
  exec(kSchema, "cannot create the tables");
  {
    Statement s(db_,
                "INSERT INTO job(id, job_text, job_hash, code_version, dof, items) "
                "VALUES(1, ?, ?, ?, ?, ?)");
    sqlite3_bind_text(s.get(), 1, identity.job_text.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(s.get(), 2, identity.job_hash.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(s.get(), 3, identity.code_version.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_int(s.get(), 4, identity.dof);
    sqlite3_bind_int64(s.get(), 5, item_count(*spec));
    const int code = sqlite3_step(s.get());
    if (code != SQLITE_DONE)
      fail("cannot write the job", code);
  }
  {
    Statement s(db_, "INSERT INTO items(id, x_m, y_m, z_m, redundancy_rad) VALUES(?, ?, ?, ?, ?)");
    const std::int64_t n = item_count(*spec);
    for (std::int64_t id = 0; id < n; ++id) {
      const AtlasItem it = item(*spec, id);
      sqlite3_bind_int64(s.get(), 1, id);
      sqlite3_bind_double(s.get(), 2, it.position_m.x());
      sqlite3_bind_double(s.get(), 3, it.position_m.y());
      sqlite3_bind_double(s.get(), 4, it.position_m.z());
      sqlite3_bind_double(s.get(), 5, it.redundancy_rad);
      const int code = sqlite3_step(s.get());
      if (code != SQLITE_DONE)
        fail("cannot write the items", code);
      sqlite3_reset(s.get());
    }
  }
  exec("COMMIT", "cannot write");
}

AtlasStore::AtlasStore(const std::filesystem::path& file, const StoreIdentity& identity,
                       const AtlasSpec& spec, bool restart)
    : file_(file) {
  try {
    open(false);
    check_identity(identity, restart, &spec);
  } catch (...) {
    sqlite3_close(db_);
    throw;
  }
}

AtlasStore::AtlasStore(const std::filesystem::path& file, const StoreIdentity& identity)
    : file_(file) {
  try {
    open(true);
    check_identity(identity, false, nullptr);
  } catch (...) {
    sqlite3_close(db_);
    throw;
  }
}

AtlasStore::~AtlasStore() {
  sqlite3_close(db_);
}

std::int64_t AtlasStore::item_total() const {
  Statement s(db_, "SELECT items FROM job WHERE id = 1");
  if (s.prepared() != SQLITE_OK || sqlite3_step(s.get()) != SQLITE_ROW)
    fail("cannot read the job", sqlite3_errcode(db_));
  return sqlite3_column_int64(s.get(), 0);
}

std::vector<std::int64_t> AtlasStore::pending() const {
  Statement s(db_, "SELECT id FROM items WHERE status = 0 ORDER BY id");
  if (s.prepared() != SQLITE_OK)
    fail("cannot read the items", s.prepared());
  std::vector<std::int64_t> ids;
  int code = SQLITE_ROW;
  while ((code = sqlite3_step(s.get())) == SQLITE_ROW)
    ids.push_back(sqlite3_column_int64(s.get(), 0));
  if (code != SQLITE_DONE)
    fail("cannot read the items", code);
  return ids;
}

void AtlasStore::commit(const std::vector<std::pair<std::int64_t, AtlasResult>>& batch) {
  if (batch.empty())
    return;
  exec("BEGIN", "cannot write");
  {
    Statement insert(db_,
                     "INSERT INTO results(item_id, reachable, lowest_fn_hz, "
                     "compliance_feed_m_per_n, compliance_normal_m_per_n, "
                     "compliance_axial_m_per_n, condition_number, depth_min_m, "
                     "speed_at_min_rad_s, depth_max_m, speed_at_max_rad_s, q_rad) "
                     "VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
    Statement done(db_, "UPDATE items SET status = 1 WHERE id = ?");
    if (insert.prepared() != SQLITE_OK || done.prepared() != SQLITE_OK)
      fail("cannot write the results", sqlite3_errcode(db_));
    for (const auto& [id, r] : batch) {
      sqlite3_stmt* s = insert.get();
      sqlite3_bind_int64(s, 1, id);
      sqlite3_bind_int(s, 2, r.reachable ? 1 : 0);
      const double values[] = {r.lowest_frequency_hz,       r.compliance_feed_m_per_n,
                               r.compliance_normal_m_per_n, r.compliance_axial_m_per_n,
                               r.condition_number,          r.depth_min_m,
                               r.speed_at_min_rad_s,        r.depth_max_m,
                               r.speed_at_max_rad_s};
      for (int i = 0; i < 9; ++i)
        sqlite3_bind_double(s, 3 + i, values[i]);
      if (r.reachable)
        sqlite3_bind_blob(s, 12, r.q.data(), static_cast<int>(r.q.size() * sizeof(double)),
                          SQLITE_TRANSIENT);
      else
        sqlite3_bind_null(s, 12);
      int code = sqlite3_step(s);
      if (code != SQLITE_DONE)
        fail("cannot write the result of item " + std::to_string(id), code);
      sqlite3_reset(s);
      sqlite3_bind_int64(done.get(), 1, id);
      code = sqlite3_step(done.get());
      if (code != SQLITE_DONE)
        fail("cannot mark item " + std::to_string(id), code);
      sqlite3_reset(done.get());
    }
  }
  exec("COMMIT", "cannot commit");
}

std::vector<StoredItem> AtlasStore::finished() const {
  Statement s(db_,
              "SELECT i.id, i.x_m, i.y_m, i.z_m, i.redundancy_rad, r.reachable, r.lowest_fn_hz, "
              "r.compliance_feed_m_per_n, r.compliance_normal_m_per_n, "
              "r.compliance_axial_m_per_n, r.condition_number, r.depth_min_m, "
              "r.speed_at_min_rad_s, r.depth_max_m, r.speed_at_max_rad_s, r.q_rad "
              "FROM items i JOIN results r ON r.item_id = i.id ORDER BY i.id");
  if (s.prepared() != SQLITE_OK)
    fail("cannot read the results", s.prepared());
  std::vector<StoredItem> items;
  int code = SQLITE_ROW;
  while ((code = sqlite3_step(s.get())) == SQLITE_ROW) {
    sqlite3_stmt* st = s.get();
    StoredItem row;
    row.item.id = sqlite3_column_int64(st, 0);
    row.item.position_m = {sqlite3_column_double(st, 1), sqlite3_column_double(st, 2),
                           sqlite3_column_double(st, 3)};
    row.item.redundancy_rad = sqlite3_column_double(st, 4);
    AtlasResult& r = row.result;
    r.reachable = sqlite3_column_int(st, 5) != 0;
    double* fields[] = {&r.lowest_frequency_hz,       &r.compliance_feed_m_per_n,
                        &r.compliance_normal_m_per_n, &r.compliance_axial_m_per_n,
                        &r.condition_number,          &r.depth_min_m,
                        &r.speed_at_min_rad_s,        &r.depth_max_m,
                        &r.speed_at_max_rad_s};
    for (int i = 0; i < 9; ++i)
      *fields[i] = sqlite3_column_double(st, 6 + i);
    const int bytes = sqlite3_column_bytes(st, 15);
    if (r.reachable && bytes > 0) {
      r.q.resize(bytes / static_cast<int>(sizeof(double)));
      std::memcpy(r.q.data(), sqlite3_column_blob(st, 15),
                  static_cast<std::size_t>(r.q.size()) * sizeof(double));
    }
    items.push_back(std::move(row));
  }
  if (code != SQLITE_DONE)
    fail("cannot read the results", code);
  return items;
}

}  // namespace robomill::atlas
