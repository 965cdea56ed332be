#pragma once
// SQLite connections and statements that close and finalize themselves, and a
// connection whose failures are Error(IO) naming the file.
#include <sqlite3.h>

#include <memory>
#include <string>

#include "parcelscope/core/Error.h"

namespace parcelscope::io::detail {

struct DbClose {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};
using Db = std::unique_ptr<sqlite3, DbClose>;

struct StmtFinalize {
  void operator()(sqlite3_stmt* s) const { sqlite3_finalize(s); }
};
using Stmt = std::unique_ptr<sqlite3_stmt, StmtFinalize>;

/// The database at `path`, opened with `flags`; every failure is told as
/// "PATH: CONTEXTWHAT (SQLite's message)".
class Connection {
public:
  Connection(std::string path, int flags, std::string context) : path_(std::move(path)), context_(std::move(context)) {
    sqlite3* raw = nullptr;
    const int opened = sqlite3_open_v2(path_.c_str(), &raw, flags, nullptr);
    db_.reset(raw);
    if (opened != SQLITE_OK) throw fail("cannot open");
  }
  sqlite3* get() const { return db_.get(); }
  Error fail(const std::string& what) const {
    return ioError(path_ + ": " + context_ + what + " (" + (db_ ? sqlite3_errmsg(db_.get()) : "out of memory") + ")");
  }
  void exec(const std::string& sql) const {
    if (sqlite3_exec(db_.get(), sql.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK) throw fail(sql);
  }
  Stmt prepare(const std::string& sql) const {
    sqlite3_stmt* s = nullptr;
    if (sqlite3_prepare_v2(db_.get(), sql.c_str(), -1, &s, nullptr) != SQLITE_OK) throw fail(sql);
    return Stmt(s);
  }
  /// Closes, failing as a write would.
  void close(const std::string& what) {
    if (sqlite3_close(db_.release()) != SQLITE_OK) throw ioError(path_ + ": " + what);
  }

private:
  std::string path_, context_;
  Db db_;
};

}  // namespace parcelscope::io::detail
