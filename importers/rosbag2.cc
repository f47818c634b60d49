// The rosbag2 reader: metadata.yaml names the storage (SQLite .db3 files or MCAP files), the files and their zstd
// compression (none, per file or per message); each .db3 is opened read-only and immutable (a bag left in WAL mode is
// read as its main file holds it), a compressed one is decompressed into memory.
#include <sqlite3.h>
#include <zstd.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "common/yaml_keys.h"
#include "importers/internal/bag.h"
#include "importers/internal/mcap_reader.h"
#include "importers/internal/rosbag2_topics.h"

namespace roamlab::importers::internal {
namespace {

namespace fs = std::filesystem;

enum class Compression { kNone, kFile, kMessage };  // zstd per file or per message

struct Metadata {
  std::string storage;             // "sqlite3" or "mcap"
  std::vector<std::string> files;  // relative_file_paths
  std::string compression_format;  // "" when none
  std::string compression_mode;    // "FILE" or "MESSAGE"
  Compression compression = Compression::kNone;
};

std::string Scalar(const YAML::Node& map, const char* key) {
  const YAML::Node node = map[key];
  return node && node.IsScalar() ? node.as<std::string>() : "";
}

// Reads the parts of metadata.yaml the reader needs; the problem as "<path>[:<line>]: <problem>", or "".
std::string ReadMetadata(const std::string& path, Metadata* out) {
  try {
    const YAML::Node root = YAML::LoadFile(path);
    if (const std::string problem = DuplicateKeyProblem(root); !problem.empty()) return path + ":" + problem;
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
    return path + (e.mark.is_null() ? "" : ":" + std::to_string(e.mark.line + 1)) + ": " + e.msg;
  }
  return "";
}

// Sets metadata->compression from its format and mode when this reader reads them; the problem otherwise.
std::string ReadCompression(const std::string& path, Metadata* metadata) {
  std::string mode = metadata->compression_mode;
  for (char& ch : mode) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  const std::string& format = metadata->compression_format;
  if (format.empty() || format == "none") {
    metadata->compression = Compression::kNone;
  } else if (format == "zstd" && (mode == "file" || mode == "message")) {
    metadata->compression = mode == "file" ? Compression::kFile : Compression::kMessage;
  } else {
    return path + ": compression_format '" + format + "' with compression_mode '" + metadata->compression_mode +
           "', which this reader does not read (only zstd, by file or by message)";
  }
  return "";
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

bool IsSqlite(std::string_view head) {
  static constexpr std::string_view kHeader("SQLite format 3\0", 16);
  return head.substr(0, kHeader.size()) == kHeader;
}

// The open database's topics and messages, appended to `bag`; `size_hint` bytes are reserved for the messages.
std::string AppendDatabase(sqlite3* db, const std::string& path, std::size_t size_hint, Bag* bag) {
  std::map<std::int64_t, std::size_t> topic_ids;
  if (std::string problem = ReadTopics(db, path, bag, &topic_ids); !problem.empty()) return problem;
  std::string& bytes = bag->storage.emplace_back();
  bytes.reserve(size_hint);
  std::vector<StoredMessage> stored;
  if (std::string problem = ReadMessages(db, path, topic_ids, &bytes, &stored); !problem.empty()) return problem;
  const std::string_view all = bytes;
  bag->messages.reserve(bag->messages.size() + stored.size());
  for (const StoredMessage& m : stored)
    bag->messages.push_back({m.topic, Time::FromNanoseconds(m.timestamp_ns), all.substr(m.offset, m.size)});
  return "";
}

// Appends one .db3 file's topics and messages to `bag`.
std::string AppendDb3(const std::string& path, Bag* bag) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return path + ": no such file";
  char head[16] = {};
  std::ifstream file(path, std::ios::binary);
  if (!file) return path + ": cannot open the file";
  file.read(head, sizeof(head));
  if (!IsSqlite(std::string_view(head, static_cast<std::size_t>(file.gcount()))))
    return path + ": not an SQLite database";
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(FileUri(path).c_str(), &raw, SQLITE_OPEN_READONLY | SQLITE_OPEN_URI, nullptr);
  Database db(raw, &sqlite3_close);
  if (rc != SQLITE_OK) return path + ": cannot open the database (" + (raw ? sqlite3_errmsg(raw) : "no memory") + ")";
  return AppendDatabase(db.get(), path, static_cast<std::size_t>(fs::file_size(path, ec)), bag);
}

// Appends the database whose file content is `image` (a decompressed .db3.zstd, named `path`) to `bag`.
std::string AppendDb3Image(const std::string& path, std::string image, Bag* bag) {
  if (image.size() < 100 || !IsSqlite(image)) return path + ": the decompressed file is not an SQLite database";
  image[18] = image[19] = 1;  // a WAL-mode file is read as the complete rollback-journal file it is
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(":memory:", &raw, SQLITE_OPEN_READWRITE, nullptr);
  Database db(raw, &sqlite3_close);
  if (rc != SQLITE_OK ||
      sqlite3_deserialize(db.get(), "main", reinterpret_cast<unsigned char*>(image.data()),
                          static_cast<sqlite3_int64>(image.size()), static_cast<sqlite3_int64>(image.size()),
                          SQLITE_DESERIALIZE_READONLY) != SQLITE_OK)
    return path + ": cannot open the decompressed database";
  return AppendDatabase(db.get(), path, image.size(), bag);
}

// The whole zstd-compressed file at `path` (one or more frames) into `out`.
std::string ReadZstdFile(const std::string& path, std::string* out) {
  std::string compressed;
  if (std::string problem = ReadFileBytes(path, &compressed); !problem.empty()) return problem;
  const std::unique_ptr<ZSTD_DCtx, decltype(&ZSTD_freeDCtx)> dctx(ZSTD_createDCtx(), &ZSTD_freeDCtx);
  ZSTD_inBuffer in{compressed.data(), compressed.size(), 0};
  std::size_t produced = 0;
  try {
    out->resize(std::max<std::size_t>(4 * compressed.size(), std::size_t{1} << 16));
    while (true) {
      if (produced == out->size()) out->resize(2 * out->size());
      ZSTD_outBuffer chunk{out->data(), out->size(), produced};
      const std::size_t rc = ZSTD_decompressStream(dctx.get(), &chunk, &in);
      if (ZSTD_isError(rc)) return path + ": the zstd data does not decompress (" + ZSTD_getErrorName(rc) + ")";
      produced = chunk.pos;
      if (rc == 0 && in.pos == in.size) break;
      if (in.pos == in.size && chunk.pos < chunk.size) return path + ": the zstd data ends inside a frame (truncated)";
    }
  } catch (const std::exception&) {
    return path + ": too large to decompress in memory";
  }
  out->resize(produced);
  return "";
}

// Replaces the data of bag->messages[first...] (each one zstd frame stating its size) with its decompressed bytes.
std::string DecompressMessages(const std::string& path, std::size_t first, Bag* bag) {
  constexpr unsigned long long kMaxMessageBytes = 1ull << 30;
  const auto where = [&](std::size_t i) {
    return path + ": message " + std::to_string(i - first) + " (topic " + bag->topics[bag->messages[i].topic].name +
           ")";
  };
  std::vector<std::size_t> sizes;
  std::size_t total = 0;
  for (std::size_t i = first; i < bag->messages.size(); ++i) {
    const std::string_view data = bag->messages[i].data;
    const unsigned long long size = ZSTD_getFrameContentSize(data.data(), data.size());
    if (size == ZSTD_CONTENTSIZE_ERROR || size == ZSTD_CONTENTSIZE_UNKNOWN || size > kMaxMessageBytes)
      return where(i) + ": not a zstd frame that states its size";
    sizes.push_back(static_cast<std::size_t>(size));
    total += sizes.back();
  }
  std::string* out = nullptr;
  try {
    out = &bag->storage.emplace_back(total, '\0');
  } catch (const std::exception&) {
    return path + ": the decompressed messages are too large for memory";
  }
  std::size_t offset = 0;
  for (std::size_t i = first; i < bag->messages.size(); ++i) {
    const std::size_t size = sizes[i - first];
    const std::string_view data = bag->messages[i].data;
    const std::size_t n = ZSTD_decompress(out->data() + offset, size, data.data(), data.size());
    if (ZSTD_isError(n) || n != size) return where(i) + ": the zstd frame does not decompress to its stated size";
    bag->messages[i].data = std::string_view(*out).substr(offset, size);
    offset += size;
  }
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

// Appends one file of the bag, decompressing it or its messages as the metadata says.
std::string AppendFile(const Metadata& metadata, const std::string& file, Bag* bag) {
  const std::size_t first = bag->messages.size();
  std::string problem;
  if (metadata.compression == Compression::kFile) {
    std::string content;
    problem = ReadZstdFile(file, &content);
    if (problem.empty())
      problem = metadata.storage == "sqlite3" ? AppendDb3Image(file, std::move(content), bag)
                                              : AppendMcap(file, std::move(content), bag);
  } else if (metadata.storage == "sqlite3") {
    problem = AppendDb3(file, bag);
  } else {
    std::string content;
    problem = ReadFileBytes(file, &content);
    if (problem.empty()) problem = AppendMcap(file, std::move(content), bag);
  }
  if (problem.empty() && metadata.compression == Compression::kMessage) problem = DecompressMessages(file, first, bag);
  return problem;
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
    if (std::string problem = ReadCompression(metadata_path, &metadata); !problem.empty())
      return Status::Error(problem);
  } else if (extension != ".db3") {
    return Status::Error((is_dir ? path : metadata_path) +
                         ": no metadata.yaml (not a rosbag2 bag directory; one .db3 file of a bag is read alone)");
  }
  Bag bag;
  if (extension == ".db3") {  // one file of the bag: its own tables describe its topics
    bag.format = "rosbag2 SQLite";
    std::string problem = AppendDb3(path, &bag);
    if (problem.empty() && metadata.compression == Compression::kMessage) problem = DecompressMessages(path, 0, &bag);
    if (!problem.empty()) return Status::Error(problem);
    return bag;
  }
  if (metadata.storage != "sqlite3" && metadata.storage != "mcap")
    return Status::Error(metadata_path + ": storage_identifier '" + metadata.storage +
                         "', which this reader does not read (only sqlite3 and mcap)");
  bag.format = metadata.storage == "sqlite3" ? "rosbag2 SQLite" : "rosbag2 MCAP";
  for (const std::string& relative : metadata.files) {
    if (std::string problem = AppendFile(metadata, ResolveFile(dir, relative), &bag); !problem.empty())
      return Status::Error(problem);
  }
  return bag;
}

}  // namespace roamlab::importers::internal
