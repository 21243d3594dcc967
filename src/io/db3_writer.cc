#include "src/io/db3_writer.h"

#include <sqlite3.h>

#include <cstdio>

namespace swarmlio::io::internal {

Db3Writer::Db3Writer() = default;

Db3Writer::~Db3Writer() {
  if (db_ != nullptr) static_cast<void>(Close());
}

Status Db3Writer::Error(const std::string& what) const {
  return Status::IoError("'" + path_ + "': " + what + ": " +
                         (db_ != nullptr ? sqlite3_errmsg(db_) : "cannot open"));
}

Status Db3Writer::Execute(const std::string& sql) {
  char* message = nullptr;
  if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &message) != SQLITE_OK) {
    const std::string text = message != nullptr ? message : "unknown error";
    sqlite3_free(message);
    return Status::IoError("'" + path_ + "': " + text);
  }
  return Status::Ok();
}

Status Db3Writer::Open(const std::string& path) {
  path_ = path;
  std::remove(path.c_str());  // a new log, never appended to an old one
  if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) !=
      SQLITE_OK) {
    const Status status = Error("cannot create");
    sqlite3_close(db_);
    db_ = nullptr;
    return status;
  }
  SWARMLIO_RETURN_IF_ERROR(Execute(
      "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);"
      "INSERT INTO schema VALUES (3, 'humble');"
      "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
      "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, "
      "timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
      "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
      "BEGIN TRANSACTION;"));
  if (sqlite3_prepare_v2(db_,
                         "INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)", -1,
                         &insert_message_, nullptr) != SQLITE_OK) {
    return Error("prepare");
  }
  return Status::Ok();
}

Status Db3Writer::AddTopic(const std::string& name, const std::string& type, int64_t* id) {
  if (db_ == nullptr) return Status::FailedPrecondition("'" + path_ + "': writer is closed");
  sqlite3_stmt* statement = nullptr;
  if (sqlite3_prepare_v2(db_,
                         "INSERT INTO topics (name, type, serialization_format, "
                         "offered_qos_profiles) VALUES (?, ?, 'cdr', '')",
                         -1, &statement, nullptr) != SQLITE_OK) {
    sqlite3_finalize(statement);
    return Error("prepare");
  }
  sqlite3_bind_text(statement, 1, name.c_str(), -1, SQLITE_TRANSIENT);
  sqlite3_bind_text(statement, 2, type.c_str(), -1, SQLITE_TRANSIENT);
  const int rc = sqlite3_step(statement);
  sqlite3_finalize(statement);
  if (rc != SQLITE_DONE) return Error("adding topic '" + name + "'");
  *id = sqlite3_last_insert_rowid(db_);
  return Status::Ok();
}

Status Db3Writer::WriteMessage(int64_t topic_id, int64_t timestamp_ns,
                               const std::vector<uint8_t>& data) {
  if (db_ == nullptr) return Status::FailedPrecondition("'" + path_ + "': writer is closed");
  sqlite3_reset(insert_message_);
  sqlite3_bind_int64(insert_message_, 1, topic_id);
  sqlite3_bind_int64(insert_message_, 2, timestamp_ns);
  sqlite3_bind_blob(insert_message_, 3, data.data(), static_cast<int>(data.size()),
                    SQLITE_STATIC);
  if (sqlite3_step(insert_message_) != SQLITE_DONE) return Error("writing a message");
  return Status::Ok();
}

Status Db3Writer::Close() {
  if (db_ == nullptr) return Status::Ok();
  sqlite3_finalize(insert_message_);
  insert_message_ = nullptr;
  const Status status = Execute("COMMIT;");
  if (sqlite3_close(db_) != SQLITE_OK && status.ok()) {
    const Status close = Error("close");
    db_ = nullptr;
    return close;
  }
  db_ = nullptr;
  return status;
}

}  // namespace swarmlio::io::internal
