// The rosbag2 reader: metadata.yaml names the storage (SQLite .db3 files or MCAP files) and the files; each .db3 is
// opened read-only and immutable (a bag left in WAL mode is read as its main file holds it).
#include <sqlite3.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "importers/internal/bag.h"
#include "importers/internal/mcap_reader.h"
#include "importers/internal/rosbag2_topics.h"

namespace roamlab::importers::internal {
namespace {

namespace fs = std::filesystem;

struct Metadata {
  std::string storage;             // "sqlite3" or "mcap"
  std::vector<std::string> files;  // relative_file_paths
  std::string compression_format;  // "" when none
  std::string compression_mode;
};

std::string Scalar(const YAML::Node& map, const char* key) {
  const YAML::Node node = map[key];
  return node && node.IsScalar() ? node.as<std::string>() : "";
}

// Reads the parts of metadata.yaml the reader needs; the problem as "<path>[:<line>]: <problem>", or "".
std::string ReadMetadata(const std::string& path, Metadata* out) {
  try {
    const YAML::Node root = YAML::LoadFile(path);
    const YAML::Node info = root.IsMap() ? root["rosbag2_bagfile_information"] : YAML::Node();
    if (!info || !info.IsMap())
      return path + ": no 'rosbag2_bagfile_information' mapping (not a rosbag2 metadata.yaml)";
    out->storage = Scalar(info, "storage_identifier");
    if (out->storage.empty()) return path + ": no storage_identifier";
    const YAML::Node files = info["relative_file_paths"];
    if (!files || !files.IsSequence() || files.size() == 0) return path + ": no relative_file_paths";
    for (const YAML::Node& file : files) {
      if (!file.IsScalar()) return path + ":" + std::to_string(file.Mark().line + 1) + ": a file path is not a string";
      out->files.push_back(file.as<std::string>());
    }
    out->compression_format = Scalar(info, "compression_format");
    out->compression_mode = Scalar(info, "compression_mode");
  } catch (const YAML::Exception& e) {
    return path + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg;
  }
  return "";
}

// The metadata's compression, when this reader can read it; the problem otherwise.
std::string CheckCompression(const std::string& path, const Metadata& metadata) {
  if (metadata.compression_format.empty() || metadata.compression_format == "none") return "";
  return path + ": compressed bag (compression_format '" + metadata.compression_format + "', mode '" +
         metadata.compression_mode + "'), which this reader does not read; decompress it first (ros2 bag decompress)";
}

using Database = std::unique_ptr<sqlite3, decltype(&sqlite3_close)>;
using Statement = std::unique_ptr<sqlite3_stmt, decltype(&sqlite3_finalize)>;

// "file:" URI of a path, with the characters a URI gives meaning to escaped.
std::string FileUri(const std::string& path) {
  std::string uri = "file:";
  for (const char ch : path) {
    if (ch == '%' || ch == '?' || ch == '#') {
      static const char kDigits[] = "0123456789ABCDEF";
      const auto byte = static_cast<unsigned char>(ch);
      uri += {'%', kDigits[byte >> 4], kDigits[byte & 0xF]};
    } else {
      uri += ch;
    }
  }
  return uri + "?immutable=1";
}

std::string Prepare(sqlite3* db, const std::string& path, const char* table, const char* sql, Statement* out) {
  sqlite3_stmt* stmt = nullptr;
  if (sqlite3_prepare_v2(db, sql, -1, &stmt, nullptr) != SQLITE_OK) {
    const std::string message = sqlite3_errmsg(db);
    if (message.find("no such table") != std::string::npos)
      return path + ": no '" + table + "' table (not a rosbag2 database)";
    return path + ": cannot read the '" + table + "' table (" + message + ")";
  }
  out->reset(stmt);
  return "";
}

std::string Text(sqlite3_stmt* stmt, int column) {
  const unsigned char* text = sqlite3_column_text(stmt, column);
  return text ? reinterpret_cast<const char*>(text) : "";
}

// The topics table: topic id -> index into bag->topics.
std::string ReadTopics(sqlite3* db, const std::string& path, Bag* bag, std::map<std::int64_t, std::size_t>* ids) {
  Statement stmt(nullptr, &sqlite3_finalize);
  if (std::string problem =
          Prepare(db, path, "topics", "SELECT id, name, type, serialization_format FROM topics", &stmt);
      !problem.empty())
    return problem;
  int rc = SQLITE_ROW;
  while ((rc = sqlite3_step(stmt.get())) == SQLITE_ROW) {
    const BagTopic topic{Text(stmt.get(), 1), TypeWithoutMsg(Text(stmt.get(), 2)), Encoding::kCdr};
    const std::string format = Text(stmt.get(), 3);
    if (format != "cdr")
      return path + ": topic " + topic.name + " has serialization format '" + format +
             "', which this reader does not decode (only cdr)";
    std::size_t index = 0;
    if (std::string problem = FindOrAddTopic(topic, bag, &index); !problem.empty()) return path + ": " + problem;
    (*ids)[sqlite3_column_int64(stmt.get(), 0)] = index;
  }
  if (rc != SQLITE_DONE) return path + ": cannot read the 'topics' table (" + sqlite3_errmsg(db) + ")";
  return "";
}

struct StoredMessage {
  std::size_t topic;
  std::int64_t timestamp_ns;
  std::size_t offset;  // into the file's message bytes
  std::size_t size;
};

// The messages table, its blobs appended to `bytes`, in the order of the timestamps (ties in row order).
std::string ReadMessages(sqlite3* db, const std::string& path, const std::map<std::int64_t, std::size_t>& topic_ids,
                         std::string* bytes, std::vector<StoredMessage>* out) {
  Statement stmt(nullptr, &sqlite3_finalize);
  if (std::string problem =
          Prepare(db, path, "messages", "SELECT id, topic_id, timestamp, data FROM messages ORDER BY id", &stmt);
      !problem.empty())
    return problem;
  int rc = SQLITE_ROW;
  while ((rc = sqlite3_step(stmt.get())) == SQLITE_ROW) {
    const std::string row = path + ": message id " + std::to_string(sqlite3_column_int64(stmt.get(), 0));
    const auto topic = topic_ids.find(sqlite3_column_int64(stmt.get(), 1));
    if (topic == topic_ids.end()) return row + " refers to a topic id not in the topics table";
    if (sqlite3_column_type(stmt.get(), 2) != SQLITE_INTEGER) return row + ": the timestamp is not an integer";
    const int type = sqlite3_column_type(stmt.get(), 3);
    if (type != SQLITE_BLOB && type != SQLITE_NULL) return row + ": the data is not a blob";
    const void* blob = sqlite3_column_blob(stmt.get(), 3);
    const auto size = static_cast<std::size_t>(sqlite3_column_bytes(stmt.get(), 3));
    out->push_back({topic->second, sqlite3_column_int64(stmt.get(), 2), bytes->size(), size});
    if (size > 0) bytes->append(static_cast<const char*>(blob), size);
  }
  if (rc != SQLITE_DONE) return path + ": cannot read the 'messages' table (" + sqlite3_errmsg(db) + ")";
  std::stable_sort(out->begin(), out->end(),
                   [](const StoredMessage& a, const StoredMessage& b) { return a.timestamp_ns < b.timestamp_ns; });
  return "";
}

std::string CheckSqliteHeader(const std::string& path) {
  static constexpr char kHeader[] = "SQLite format 3";  // with its terminating NUL: the file's first 16 bytes
  char head[sizeof(kHeader)] = {};
  std::ifstream file(path, std::ios::binary);
  if (!file) return path + ": cannot open the file";
  file.read(head, sizeof(head));
  if (file.gcount() != sizeof(head) || std::memcmp(head, kHeader, sizeof(kHeader)) != 0)
    return path + ": not an SQLite database";
  return "";
}

// Appends one .db3 file's topics and messages to `bag`.
std::string AppendDb3(const std::string& path, Bag* bag) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return path + ": no such file";
  if (std::string problem = CheckSqliteHeader(path); !problem.empty()) return problem;
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(FileUri(path).c_str(), &raw, SQLITE_OPEN_READONLY | SQLITE_OPEN_URI, nullptr);
  Database db(raw, &sqlite3_close);
  if (rc != SQLITE_OK) return path + ": cannot open the database (" + (raw ? sqlite3_errmsg(raw) : "no memory") + ")";
  std::map<std::int64_t, std::size_t> topic_ids;
  if (std::string problem = ReadTopics(db.get(), path, bag, &topic_ids); !problem.empty()) return problem;
  std::string& bytes = bag->storage.emplace_back();
  bytes.reserve(static_cast<std::size_t>(fs::file_size(path, ec)));  // the blobs take at most the file's size
  std::vector<StoredMessage> stored;
  if (std::string problem = ReadMessages(db.get(), path, topic_ids, &bytes, &stored); !problem.empty()) return problem;
  const std::string_view all = bytes;
  bag->messages.reserve(bag->messages.size() + stored.size());
  for (const StoredMessage& m : stored)
    bag->messages.push_back({m.topic, Time::FromNanoseconds(m.timestamp_ns), all.substr(m.offset, m.size)});
  return "";
}

// A file named in metadata.yaml: relative to the bag directory (or, in bags of the first metadata versions, to the
// directory above it).
std::string ResolveFile(const fs::path& dir, const std::string& relative) {
  std::error_code ec;
  const fs::path in_dir = dir / relative;
  if (fs::exists(in_dir, ec)) return in_dir.string();
  const fs::path above = dir.parent_path() / relative;
  if (!relative.empty() && fs::exists(above, ec)) return above.string();
  return in_dir.string();
}

std::string AppendFile(const std::string& storage, const std::string& file, Bag* bag) {
  if (storage == "sqlite3") return AppendDb3(file, bag);
  std::string content;
  if (std::string problem = ReadFileBytes(file, &content); !problem.empty()) return problem;
  return AppendMcap(file, std::move(content), bag);
}

}  // namespace

Result<Bag> ReadRosbag2(const std::string& path) {
  std::error_code ec;
  const bool is_dir = fs::is_directory(path, ec);
  const std::string extension = fs::path(path).extension().string();
  if (!is_dir && extension != ".yaml" && extension != ".db3")
    return Status::Error(path + ": not a rosbag2 bag (expected its directory, its metadata.yaml or a .db3 file)");
  const fs::path dir = is_dir ? fs::path(path) : fs::path(path).parent_path();
  const std::string metadata_path = (dir / "metadata.yaml").string();
  const bool has_metadata = fs::is_regular_file(metadata_path, ec);
  Metadata metadata;
  if (has_metadata) {
    if (std::string problem = ReadMetadata(metadata_path, &metadata); !problem.empty()) return Status::Error(problem);
    if (std::string problem = CheckCompression(metadata_path, metadata); !problem.empty())
      return Status::Error(problem);
  } else if (extension != ".db3") {
    return Status::Error((is_dir ? path : metadata_path) + ": no metadata.yaml (not a rosbag2 bag directory)");
  }
  Bag bag;
  if (extension == ".db3") {  // one file of the bag: its own tables describe its topics
    bag.format = "rosbag2 SQLite";
    if (std::string problem = AppendDb3(path, &bag); !problem.empty()) return Status::Error(problem);
    return bag;
  }
  if (metadata.storage != "sqlite3" && metadata.storage != "mcap")
    return Status::Error(metadata_path + ": storage_identifier '" + metadata.storage +
                         "', which this reader does not read (only sqlite3 and mcap)");
  bag.format = metadata.storage == "sqlite3" ? "rosbag2 SQLite" : "rosbag2 MCAP";
  for (const std::string& relative : metadata.files) {
    if (std::string problem = AppendFile(metadata.storage, ResolveFile(dir, relative), &bag); !problem.empty())
      return Status::Error(problem);
  }
  return bag;
}

}  // namespace roamlab::importers::internal
