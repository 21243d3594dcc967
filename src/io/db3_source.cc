#include "src/io/db3_source.h"

#include <sqlite3.h>

#include <cstring>
#include <fstream>
#include <map>
#include <utility>
#include <vector>

namespace swarmlio::io::internal {
namespace {

constexpr char kSqliteMagic[] = "SQLite format 3";  // + NUL: 16 bytes

struct DbCloser {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};
struct StatementFinalizer {
  void operator()(sqlite3_stmt* statement) const { sqlite3_finalize(statement); }
};
using Db = std::unique_ptr<sqlite3, DbCloser>;
using Statement = std::unique_ptr<sqlite3_stmt, StatementFinalizer>;

Status SqliteError(const std::string& path, sqlite3* db, const std::string& action) {
  return Status::DataLoss("bag '" + path + "': " + action + ": " +
                          (db != nullptr ? sqlite3_errmsg(db) : "cannot open"));
}

Status Prepare(const std::string& path, sqlite3* db, const std::string& sql, Statement* statement) {
  sqlite3_stmt* raw = nullptr;
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &raw, nullptr) != SQLITE_OK) {
    sqlite3_finalize(raw);
    return SqliteError(path, db, "'" + sql + "'");
  }
  statement->reset(raw);
  return Status::Ok();
}

std::string Text(sqlite3_stmt* statement, int column) {
  const unsigned char* text = sqlite3_column_text(statement, column);
  return text == nullptr ? std::string() : reinterpret_cast<const char*>(text);
}

// The messages of one topic (one or more topic ids), in timestamp order.
class Db3TopicStream : public TopicMessageStream {
 public:
  Db3TopicStream(std::string path, sqlite3* db, Statement statement)
      : path_(std::move(path)), db_(db), statement_(std::move(statement)) {}

  Status Next(uint64_t max_bytes, SourceMessage* message, bool* has_message) override {
    *has_message = false;
    if (done_) return Status::Ok();
    const int rc = sqlite3_step(statement_.get());
    if (rc == SQLITE_DONE) {
      done_ = true;
      return Status::Ok();
    }
    if (rc != SQLITE_ROW) return SqliteError(path_, db_, "reading messages");
    message->bag_time_ns = sqlite3_column_int64(statement_.get(), 0);
    message->datatype = Text(statement_.get(), 2);
    const void* blob = sqlite3_column_blob(statement_.get(), 1);
    message->size = static_cast<size_t>(sqlite3_column_bytes(statement_.get(), 1));
    message->too_large = message->size > max_bytes;
    message->data = message->too_large ? nullptr : static_cast<const uint8_t*>(blob);
    *has_message = true;
    return Status::Ok();
  }

 private:
  std::string path_;
  sqlite3* db_;
  Statement statement_;
  bool done_ = false;
};

class Db3Source : public BagSource {
 public:
  explicit Db3Source(std::string path) : path_(std::move(path)) {}

  Status Load() {
    sqlite3* raw = nullptr;
    const int rc = sqlite3_open_v2(path_.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr);
    db_.reset(raw);
    if (rc != SQLITE_OK) return SqliteError(path_, raw, "open");
    Statement topics;
    SWARMLIO_RETURN_IF_ERROR(
        Prepare(path_, db_.get(), "SELECT name, type, serialization_format FROM topics", &topics));
    int step = SQLITE_ROW;
    while ((step = sqlite3_step(topics.get())) == SQLITE_ROW) {
      SourceConnection c;
      c.topic = Text(topics.get(), 0);
      c.datatype = Text(topics.get(), 1);
      c.encoding = Text(topics.get(), 2);
      connections_.push_back(std::move(c));
    }
    if (step != SQLITE_DONE) return SqliteError(path_, db_.get(), "reading topics");
    return LoadSummaries();
  }

  const std::vector<SourceConnection>& connections() const override { return connections_; }
  int64_t message_count() const override { return message_count_; }
  int64_t start_time_ns() const override { return start_time_ns_; }
  int64_t end_time_ns() const override { return end_time_ns_; }
  const BagRecoveryStats& recovery() const override { return recovery_; }

  Status Summarize(const std::string& topic, TopicSummary* summary) override {
    const auto it = summaries_.find(topic);
    *summary = it == summaries_.end() ? TopicSummary() : it->second;
    return Status::Ok();
  }

  Status TopicTimes(const std::string& topic,
                    size_t max_count,
                    std::vector<int64_t>* times) override {
    times->clear();
    Statement statement;
    SWARMLIO_RETURN_IF_ERROR(Query(topic, "m.timestamp", &statement));
    int rc = SQLITE_ROW;
    while (times->size() < max_count && (rc = sqlite3_step(statement.get())) == SQLITE_ROW) {
      times->push_back(sqlite3_column_int64(statement.get(), 0));
    }
    if (rc != SQLITE_ROW && rc != SQLITE_DONE) {
      return SqliteError(path_, db_.get(), "reading timestamps");
    }
    return Status::Ok();
  }

  Status OpenTopic(const std::string& topic, std::unique_ptr<TopicMessageStream>* stream) override {
    Statement statement;
    SWARMLIO_RETURN_IF_ERROR(Query(topic, "m.timestamp, m.data, t.type", &statement));
    *stream = std::make_unique<Db3TopicStream>(path_, db_.get(), std::move(statement));
    return Status::Ok();
  }

 private:
  // Per topic: count and time range (one GROUP BY over the messages).
  Status LoadSummaries() {
    Statement statement;
    SWARMLIO_RETURN_IF_ERROR(Prepare(path_, db_.get(),
                                     "SELECT t.name, COUNT(*), MIN(m.timestamp), MAX(m.timestamp) "
                                     "FROM messages m JOIN topics t ON m.topic_id = t.id "
                                     "GROUP BY t.name",
                                     &statement));
    int rc = SQLITE_ROW;
    while ((rc = sqlite3_step(statement.get())) == SQLITE_ROW) {
      TopicSummary& s = summaries_[Text(statement.get(), 0)];
      s.message_count = sqlite3_column_int64(statement.get(), 1);
      s.first_time_ns = sqlite3_column_int64(statement.get(), 2);
      s.last_time_ns = sqlite3_column_int64(statement.get(), 3);
      if (message_count_ == 0 || s.first_time_ns < start_time_ns_) start_time_ns_ = s.first_time_ns;
      if (message_count_ == 0 || s.last_time_ns > end_time_ns_) end_time_ns_ = s.last_time_ns;
      message_count_ += s.message_count;
    }
    if (rc != SQLITE_DONE) return SqliteError(path_, db_.get(), "counting messages");
    return Status::Ok();
  }

  // `columns` of the messages of `topic` in timestamp order (ties: id).
  Status Query(const std::string& topic, const std::string& columns, Statement* statement) {
    SWARMLIO_RETURN_IF_ERROR(Prepare(path_, db_.get(),
                                     "SELECT " + columns +
                                         " FROM messages m JOIN topics t ON m.topic_id = t.id "
                                         "WHERE t.name = ?1 ORDER BY m.timestamp, m.id",
                                     statement));
    sqlite3_bind_text(statement->get(), 1, topic.c_str(), -1, SQLITE_TRANSIENT);
    return Status::Ok();
  }

  std::string path_;
  Db db_;
  std::vector<SourceConnection> connections_;
  std::map<std::string, TopicSummary> summaries_;
  int64_t message_count_ = 0;
  int64_t start_time_ns_ = 0;
  int64_t end_time_ns_ = 0;
  BagRecoveryStats recovery_;
};

}  // namespace

Status OpenDb3Source(const std::string& path, std::unique_ptr<BagSource>* source) {
  auto db3 = std::make_unique<Db3Source>(path);
  SWARMLIO_RETURN_IF_ERROR(db3->Load());
  *source = std::move(db3);
  return Status::Ok();
}

bool HasSqliteMagic(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  char magic[sizeof(kSqliteMagic)] = {};
  if (!file.read(magic, sizeof(magic))) return false;
  return std::memcmp(magic, kSqliteMagic, sizeof(kSqliteMagic)) == 0;
}

}  // namespace swarmlio::io::internal
