#include "experiments/runner.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <ostream>
#include <set>
#include <sstream>
#include <thread>

#include "mesh/atomic_file.hpp"
#include "mesh/error.hpp"
#include "mesh/generators.hpp"

namespace hexrefine {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// Validation context: the file and the JSON path of the value being checked.
struct SchemaPath {
  const std::string& file;
  std::string path;

  SchemaPath at(const std::string& key) const { return {file, path + "/" + key}; }
  SchemaPath at(size_t i) const { return {file, path + "/" + std::to_string(i)}; }
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(file + ": " + (path.empty() ? "/" : path) + ": " + what);
  }
};

void schema_require_object(const json& j, const SchemaPath& p) {
  if (!j.is_object()) p.fail("expected an object");
}

void schema_allow_keys(const json& j, const SchemaPath& p,
                       std::initializer_list<const char*> keys) {
  for (const auto& [k, v] : j.items()) {
    bool known = false;
    for (const char* key : keys) known = known || k == key;
    if (!known) {
      std::string list;
      for (const char* key : keys) list += std::string(list.empty() ? "" : ", ") + key;
      p.at(k).fail("unknown key (expected one of: " + list + ")");
    }
  }
}

std::string schema_string(const json& j, const SchemaPath& p) {
  if (!j.is_string() || j.get<std::string>().empty()) p.fail("expected a non-empty string");
  return j.get<std::string>();
}

int64_t schema_int(const json& j, const SchemaPath& p, int64_t min_value) {
  if (!j.is_number_integer() || j.get<int64_t>() < min_value)
    p.fail("expected an integer >= " + std::to_string(min_value));
  return j.get<int64_t>();
}

bool schema_bool(const json& j, const SchemaPath& p) {
  if (!j.is_boolean()) p.fail("expected true or false");
  return j.get<bool>();
}

std::vector<std::string> schema_strings(const json& j, const SchemaPath& p) {
  if (!j.is_array() || j.empty()) p.fail("expected a non-empty array of strings");
  std::vector<std::string> out;
  for (size_t i = 0; i < j.size(); ++i) out.push_back(schema_string(j[i], p.at(i)));
  return out;
}

json parse_mesh(const json& j, const SchemaPath& p, const std::string& base_dir) {
  schema_require_object(j, p);
  const bool has_file = j.contains("file");
  const bool has_generate = j.contains("generate");
  if (has_file == has_generate) p.fail("expected exactly one of \"generate\" or \"file\"");
  if (has_file) {
    schema_allow_keys(j, p, {"file"});
    const std::string given = schema_string(j["file"], p.at("file"));
    fs::path path(given);
    if (path.is_relative()) path = fs::path(base_dir) / path;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) p.at("file").fail("mesh file not found: " + path.string());
    return json{{"file", given}, {"path", path.lexically_normal().string()}};
  }
  const std::string kind = schema_string(j["generate"], p.at("generate"));
  const Generator* generator = nullptr;
  try {
    generator = &generator_find(kind);
  } catch (const InputError& e) {
    p.at("generate").fail(e.what());
  }
  json given = j;
  given.erase("generate");
  json out = generator_params(*generator, given, p.file + ": " + (p.path.empty() ? "" : p.path));
  out["generate"] = generator->name;
  return out;
}

RunCase parse_case(const json& j, const SchemaPath& p, const std::string& base_dir, int index) {
  schema_require_object(j, p);
  schema_allow_keys(j, p,
                    {"name", "description", "mesh", "select", "methods", "passes", "smooth",
                     "save_mesh", "options", "tags"});
  RunCase c;
  c.index = index;
  if (!j.contains("name")) p.fail("missing \"name\"");
  c.name = schema_string(j["name"], p.at("name"));
  if (!j.contains("mesh")) p.fail("missing \"mesh\"");
  c.mesh = parse_mesh(j["mesh"], p.at("mesh"), base_dir);
  if (!j.contains("select")) p.fail("missing \"select\" (use [\"all\"] to refine every hex)");
  c.select_given = schema_strings(j["select"], p.at("select"));
  for (const std::string& spec : c.select_given) {
    if (spec.compare(0, 6, "hexes:") == 0 && fs::path(spec.substr(6)).is_relative())
      c.select.push_back("hexes:" +
                         (fs::path(base_dir) / spec.substr(6)).lexically_normal().string());
    else
      c.select.push_back(spec);
  }
  c.methods = {"selective", "sheet"};
  if (j.contains("methods")) {
    c.methods = schema_strings(j["methods"], p.at("methods"));
    std::set<std::string> seen;
    for (size_t i = 0; i < c.methods.size(); ++i) {
      try {
        refine_method(c.methods[i]);
      } catch (const InputError& e) {
        p.at("methods").at(i).fail(e.what());
      }
      if (!seen.insert(c.methods[i]).second)
        p.at("methods").at(i).fail("method '" + c.methods[i] + "' listed twice");
    }
  }
  if (j.contains("passes")) {
    const int64_t passes = schema_int(j["passes"], p.at("passes"), 1);
    if (passes > 10) p.at("passes").fail("expected an integer in [1, 10]");
    c.options.passes = static_cast<int>(passes);
  }
  if (j.contains("smooth")) c.smooth = schema_bool(j["smooth"], p.at("smooth"));
  if (j.contains("save_mesh")) c.save_mesh = schema_bool(j["save_mesh"], p.at("save_mesh"));
  if (j.contains("options")) {
    const json& o = j["options"];
    const SchemaPath op = p.at("options");
    schema_require_object(o, op);
    schema_allow_keys(o, op,
                      {"ranking", "directional_order", "propagation", "ebe_only", "buffer",
                       "allow_inverted", "placement"});
    if (o.contains("ranking")) c.options.ranking = schema_bool(o["ranking"], op.at("ranking"));
    if (o.contains("directional_order")) {
      const std::string order = schema_string(o["directional_order"], op.at("directional_order"));
      if (order != "by_rank" && order != "by_hex")
        op.at("directional_order")
            .fail("expected \"by_rank\" or \"by_hex\", got \"" + order + "\"");
      c.options.directional_order =
          order == "by_hex" ? DirectionalOrder::by_hex : DirectionalOrder::by_rank;
    }
    if (o.contains("propagation"))
      c.options.propagation = schema_bool(o["propagation"], op.at("propagation"));
    if (o.contains("ebe_only")) c.options.ebe_only = schema_bool(o["ebe_only"], op.at("ebe_only"));
    if (o.contains("buffer")) {
      // A rule name; the booleans of earlier case files mean what they meant then.
      if (o["buffer"].is_boolean())
        c.options.buffer = o["buffer"].get<bool>() ? PassBuffer::transitions : PassBuffer::none;
      else
        try {
          c.options.buffer = pass_buffer_from_name(schema_string(o["buffer"], op.at("buffer")));
        } catch (const InputError& e) {
          op.at("buffer").fail(e.what());
        }
    }
    if (o.contains("allow_inverted"))
      c.options.allow_inverted = schema_bool(o["allow_inverted"], op.at("allow_inverted"));
    if (o.contains("placement")) {
      const std::string placement = schema_string(o["placement"], op.at("placement"));
      if (placement == "trilinear")
        c.options.placement.method = PlacementMethod::trilinear;
      else if (placement == "optimized")
        c.options.placement.method = PlacementMethod::optimized;
      else
        op.at("placement").fail("expected \"trilinear\" or \"optimized\"");
    }
  }
  if (j.contains("tags")) {
    schema_require_object(j["tags"], p.at("tags"));
    c.tags = j["tags"];
  }
  return c;
}

/// Line number (1-based) of byte offset `pos` in `text`.
int64_t text_line_of(const std::string& text, size_t pos) {
  pos = std::min(pos, text.size());
  return 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(pos), '\n');
}

std::string file_read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw InputError(path + ": read failed");
  return ss.str();
}

}  // namespace

RunPlan run_plan_parse(const json& root, const std::string& file, const std::string& base_dir) {
  const SchemaPath p{file, ""};
  schema_require_object(root, p);
  schema_allow_keys(root, p, {"cases", "output", "description"});
  RunPlan plan;
  plan.source = file;
  if (!root.contains("cases")) p.fail("missing \"cases\"");
  const json& cases = root["cases"];
  if (!cases.is_array() || cases.empty()) p.at("cases").fail("expected a non-empty array");
  std::set<std::string> names;
  for (size_t i = 0; i < cases.size(); ++i) {
    RunCase c = parse_case(cases[i], p.at("cases").at(i), base_dir, static_cast<int>(i));
    if (!names.insert(c.name).second)
      p.at("cases").at(i).at("name").fail("case name '" + c.name + "' used twice");
    plan.cases.push_back(std::move(c));
  }
  if (root.contains("output")) {
    fs::path out(schema_string(root["output"], p.at("output")));
    if (out.is_relative()) out = fs::path(base_dir) / out;
    plan.output = out.lexically_normal().string();
  } else {
    fs::path out = fs::path(base_dir) / fs::path(file).stem();
    plan.output = out.string() + ".jsonl";
  }
  return plan;
}

RunPlan run_plan_read(const std::string& path) {
  const std::string text = file_read_all(path);
  json root;
  try {
    root = json::parse(text);
  } catch (const json::parse_error& e) {
    throw InputError(error_at(path, text_line_of(text, e.byte > 0 ? e.byte - 1 : 0),
                              std::string("invalid JSON: ") + e.what()));
  }
  std::string base = fs::path(path).parent_path().string();
  if (base.empty()) base = ".";
  return run_plan_parse(root, path, base);
}

json run_options_to_json(const RefineOptions& o, bool smooth) {
  json j = o;
  j.erase("threads");  // the output does not depend on it
  j["smooth"] = smooth;
  return j;
}

std::string run_record_key(const std::string& case_name, const std::string& method,
                           const json& options) {
  return case_name + '\x1f' + method + '\x1f' + options.dump();
}

std::string run_record_key(const json& record) {
  if (!record.is_object() || !record.contains("case") || !record["case"].is_string() ||
      !record.contains("method") || !record["method"].is_string() || !record.contains("options"))
    throw InputError("record without \"case\", \"method\" and \"options\": " +
                     record.dump().substr(0, 120));
  return run_record_key(record["case"].get<std::string>(), record["method"].get<std::string>(),
                        record["options"]);
}

JsonlContent jsonl_read(const std::string& path) {
  JsonlContent out;
  std::error_code ec;
  if (!fs::exists(path, ec)) return out;
  const std::string text = file_read_all(path);
  size_t start = 0;
  int64_t line = 0;
  while (start < text.size()) {
    ++line;
    const size_t end = text.find('\n', start);
    const bool complete = end != std::string::npos;
    const std::string row = text.substr(start, complete ? end - start : std::string::npos);
    const size_t next = complete ? end + 1 : text.size();
    if (row.find_first_not_of(" \t\r") == std::string::npos) {
      if (complete) out.valid_text.append(text, start, next - start);
      start = next;
      continue;
    }
    json record;
    bool ok = true;
    try {
      record = json::parse(row);
    } catch (const json::parse_error&) {
      ok = false;
    }
    if (!complete) {
      // A killed writer leaves at most one partial line: the end of the file, without its
      // newline (jsonl_append writes the newline last).
      out.truncated_tail = true;
      break;
    }
    if (!ok) throw InputError(error_at(path, line, "not a JSON record"));
    try {
      run_record_key(record);
    } catch (const InputError& e) {
      throw InputError(error_at(path, line, e.what()));
    }
    out.records.push_back(std::move(record));
    out.valid_text.append(text, start, next - start);
    start = next;
  }
  return out;
}

void jsonl_append(const std::string& path, const json& record) {
  const std::string line = record.dump() + "\n";
  const int fd = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) throw OperationError(path + ": cannot open for appending");
  size_t done = 0;
  while (done < line.size()) {
    const ssize_t n = ::write(fd, line.data() + done, line.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      ::close(fd);
      throw OperationError(path + ": write failed (disk full?)");
    }
    done += static_cast<size_t>(n);
  }
  ::fdatasync(fd);
  if (::close(fd) != 0) throw OperationError(path + ": write failed on close");
}

void jsonl_write(const std::string& path, const std::vector<json>& records) {
  file_write_atomically(path, [&](std::ostream& out) {
    for (const json& r : records) out << r.dump() << '\n';
  });
}

std::pair<int, int> run_shard_parse(const std::string& text) {
  const size_t slash = text.find('/');
  auto fail = [&]() -> std::pair<int, int> {
    throw InputError("--shard: expected K/N with 1 <= K <= N (1-based), got '" + text + "'");
  };
  if (slash == std::string::npos) return fail();
  const std::string k_text = text.substr(0, slash), n_text = text.substr(slash + 1);
  for (const std::string* s : {&k_text, &n_text})
    if (s->empty() || s->size() > 6 || s->find_first_not_of("0123456789") != std::string::npos)
      return fail();
  const int k = std::stoi(k_text), n = std::stoi(n_text);
  if (n < 1 || k < 1 || k > n) return fail();
  return {k - 1, n};
}

std::string run_shard_output(const std::string& output, int shard, int count) {
  if (count <= 1) return output;
  const fs::path p(output);
  const std::string tag = ".shard-" + std::to_string(shard + 1) + "-of-" + std::to_string(count);
  return (p.parent_path() / (p.stem().string() + tag + p.extension().string())).string();
}

std::vector<json> run_records_merge(const std::vector<std::vector<json>>& inputs) {
  std::map<std::string, json> by_key;
  for (const auto& records : inputs)
    for (const json& r : records) by_key[run_record_key(r)] = r;
  struct Entry {
    int64_t case_index, method_index;
    std::string key;
    const json* record;
  };
  std::vector<Entry> entries;
  for (const auto& [key, r] : by_key)
    entries.push_back(
        {r.value("case_index", int64_t{0}), r.value("method_index", int64_t{0}), key, &r});
  std::stable_sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    if (a.case_index != b.case_index) return a.case_index < b.case_index;
    if (a.method_index != b.method_index) return a.method_index < b.method_index;
    return a.key < b.key;
  });
  std::vector<json> out;
  for (const Entry& e : entries) out.push_back(*e.record);
  return out;
}

// --- SHA-256 (FIPS 180-4) --------------------------------------------------------------------

std::string sha256_hex(std::string_view data) {
  static constexpr std::array<uint32_t, 64> k = {
      0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4,
      0xab1c5ed5, 0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe,
      0x9bdc06a7, 0xc19bf174, 0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f,
      0x4a7484aa, 0x5cb0a9dc, 0x76f988da, 0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7,
      0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967, 0x27b70a85, 0x2e1b2138, 0x4d2c6dfc,
      0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85, 0xa2bfe8a1, 0xa81a664b,
      0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070, 0x19a4c116,
      0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
      0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7,
      0xc67178f2};
  std::array<uint32_t, 8> h = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                               0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
  auto rotr = [](uint32_t x, int n) { return (x >> n) | (x << (32 - n)); };
  // Padding: a 1 bit, zeros to 56 mod 64 bytes, then the bit length as 64-bit big endian.
  std::string msg(data);
  const uint64_t bits = static_cast<uint64_t>(data.size()) * 8;
  msg.push_back(static_cast<char>(0x80));
  while (msg.size() % 64 != 56) msg.push_back('\0');
  for (int i = 7; i >= 0; --i) msg.push_back(static_cast<char>((bits >> (8 * i)) & 0xff));
  std::array<uint32_t, 64> w{};
  for (size_t block = 0; block < msg.size(); block += 64) {
    for (int i = 0; i < 16; ++i) {
      const auto* b = reinterpret_cast<const unsigned char*>(msg.data() + block + 4 * i);
      w[i] = (uint32_t{b[0]} << 24) | (uint32_t{b[1]} << 16) | (uint32_t{b[2]} << 8) | b[3];
    }
    for (int i = 16; i < 64; ++i) {
      const uint32_t s0 = rotr(w[i - 15], 7) ^ rotr(w[i - 15], 18) ^ (w[i - 15] >> 3);
      const uint32_t s1 = rotr(w[i - 2], 17) ^ rotr(w[i - 2], 19) ^ (w[i - 2] >> 10);
      w[i] = w[i - 16] + s0 + w[i - 7] + s1;
    }
    uint32_t a = h[0], b = h[1], c = h[2], d = h[3], e = h[4], f = h[5], g = h[6], hh = h[7];
    for (int i = 0; i < 64; ++i) {
      const uint32_t s1 = rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25);
      const uint32_t ch = (e & f) ^ (~e & g);
      const uint32_t t1 = hh + s1 + ch + k[i] + w[i];
      const uint32_t s0 = rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22);
      const uint32_t maj = (a & b) ^ (a & c) ^ (b & c);
      const uint32_t t2 = s0 + maj;
      hh = g;
      g = f;
      f = e;
      e = d + t1;
      d = c;
      c = b;
      b = a;
      a = t1 + t2;
    }
    h[0] += a;
    h[1] += b;
    h[2] += c;
    h[3] += d;
    h[4] += e;
    h[5] += f;
    h[6] += g;
    h[7] += hh;
  }
  std::ostringstream out;
  for (uint32_t v : h) out << std::hex << std::setw(8) << std::setfill('0') << v;
  return out.str();
}

std::string sha256_file(const std::string& path) {
  return sha256_hex(file_read_all(path));
}

// --- environment ------------------------------------------------------------------------------

std::string run_source_dir() {
#ifdef HEXREFINE_SOURCE_DIR
  return HEXREFINE_SOURCE_DIR;
#else
  return ".";
#endif
}

std::string run_shared_dir() {
  return (fs::path(run_source_dir()) / ".." / "shared").lexically_normal().string();
}

RunEnvironment run_environment_detect() {
  RunEnvironment env;
  const std::string cmd = "git -C '" + run_source_dir() + "' rev-parse HEAD 2>/dev/null";
  if (FILE* pipe = ::popen(cmd.c_str(), "r")) {
    std::array<char, 128> buf{};
    std::string text;
    size_t n;
    while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) text.append(buf.data(), n);
    if (::pclose(pipe) == 0) {
      while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())))
        text.pop_back();
      if (text.size() == 40 && text.find_first_not_of("0123456789abcdef") == std::string::npos)
        env.commit = text;
    }
  }
  if (env.commit != "unknown") {
    // Results must say whether they came from exactly that commit.
    const std::string status =
        "git -C '" + run_source_dir() + "' status --porcelain --untracked-files=no 2>/dev/null";
    if (FILE* pipe = ::popen(status.c_str(), "r")) {
      std::array<char, 64> buf{};
      env.commit_dirty = fread(buf.data(), 1, buf.size(), pipe) > 0;
      while (fread(buf.data(), 1, buf.size(), pipe) > 0) {
      }
      ::pclose(pipe);
    }
  }
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpuinfo, line)) {
    if (line.compare(0, 10, "model name") == 0) {
      const size_t colon = line.find(':');
      if (colon != std::string::npos) {
        env.cpu = line.substr(line.find_first_not_of(" \t", colon + 1));
        break;
      }
    }
  }
  env.cores = static_cast<int>(std::thread::hardware_concurrency());
#ifdef NDEBUG
  env.build_type = "release";
#else
  env.build_type = "debug";
#endif
  return env;
}

std::string run_timestamp_utc() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  ::gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::string run_mesh_file_name(const std::string& case_name, const std::string& method) {
  std::string name = case_name;
  for (char& ch : name)
    if (ch == '/' || ch == '\\' || ch == ' ' || ch == ':') ch = '_';
  return name + "." + method + ".vtu";
}

// --- the run ----------------------------------------------------------------------------------

namespace {

/// Thrown through the executor when the log cannot be appended to; deliberately not a
/// std::exception so that an executor's catch of std::exception does not swallow it.
struct RunAbort {
  OperationError error;
};

}  // namespace

RunSummary run_plan_execute(const RunPlan& plan, const RunSettings& settings,
                            const RunExecutor& execute) {
  RunSummary summary;
  std::string output = settings.output.empty()
                           ? run_shard_output(plan.output, settings.shard, settings.shard_count)
                           : settings.output;
  summary.output = output;
  std::error_code ec;
  const fs::path parent = fs::path(output).parent_path();
  if (!parent.empty()) fs::create_directories(parent, ec);

  std::set<std::string> done;
  if (settings.resume) {
    const JsonlContent existing = jsonl_read(output);
    if (existing.truncated_tail) {
      file_write_atomically(output, [&](std::ostream& out) { out << existing.valid_text; });
      if (settings.progress) *settings.progress << output << ": dropped a partial last line\n";
    }
    for (const json& r : existing.records) done.insert(run_record_key(r));
  } else {
    file_write_atomically(output, [](std::ostream&) {});
  }

  // The work list: (case, methods still to run) for this shard.
  std::vector<std::pair<const RunCase*, std::vector<std::string>>> work;
  int64_t total_pairs = 0;
  for (const RunCase& c : plan.cases) {
    if (!run_case_in_shard(c.index, settings.shard, settings.shard_count)) continue;
    const json options = run_options_to_json(c.options, c.smooth);
    std::vector<std::string> todo;
    for (const std::string& m : c.methods) {
      if (done.count(run_record_key(c.name, m, options)))
        ++summary.records_skipped;
      else
        todo.push_back(m);
    }
    if (todo.empty()) continue;
    total_pairs += static_cast<int64_t>(todo.size());
    work.emplace_back(&c, std::move(todo));
  }

  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  int64_t pairs_done = 0;
  for (size_t w = 0; w < work.size(); ++w) {
    RunCase c = *work[w].first;
    if (c.save_mesh) {
      const fs::path out(output);
      c.save_mesh_dir = (out.parent_path() / (out.stem().string() + ".meshes")).string();
      fs::create_directories(c.save_mesh_dir, ec);
    }
    const std::vector<std::string>& todo = work[w].second;
    if (settings.progress) {
      std::ostringstream line;
      line << "[case " << (w + 1) << " of " << work.size() << "] " << c.name << " (" << todo.size()
           << " method" << (todo.size() == 1 ? "" : "s") << ")  elapsed " << std::fixed
           << std::setprecision(1) << elapsed() << " s";
      if (pairs_done > 0)
        line << ", about " << elapsed() / pairs_done * (total_pairs - pairs_done) << " s left";
      *settings.progress << line.str() << std::endl;
    }
    const json options = run_options_to_json(c.options, c.smooth);
    std::set<std::string> emitted;
    auto emit = [&](const std::string& method, json fields) {
      const auto it = std::find(c.methods.begin(), c.methods.end(), method);
      if (it == c.methods.end() || emitted.count(method))
        throw OperationError("runner: executor emitted an unexpected method '" + method + "'");
      emitted.insert(method);
      json record = json::object();
      record["case"] = c.name;
      record["case_index"] = c.index;
      record["method"] = method;
      record["method_index"] = it - c.methods.begin();
      record["options"] = options;
      record["tags"] = c.tags;
      record["commit"] = settings.environment.commit;
      record["commit_dirty"] = settings.environment.commit_dirty;
      record["machine"] = {{"cpu", settings.environment.cpu},
                           {"cores", settings.environment.cores}};
      record["build_type"] = settings.environment.build_type;
      record["timestamp"] = run_timestamp_utc();
      for (auto& [k, v] : fields.items()) record[k] = std::move(v);
      if (record.contains("error")) ++summary.errors;
      try {
        jsonl_append(output, record);
      } catch (const OperationError& e) {
        throw RunAbort{e};  // not an error of this case: the log itself cannot be written
      }
      ++summary.records_written;
      ++pairs_done;
    };
    std::string failure, kind;
    try {
      execute(c, todo, emit);
    } catch (const RunAbort& abort) {
      throw abort.error;
    } catch (const InputError& e) {
      failure = e.what();
      kind = "input";
    } catch (const OperationError& e) {
      failure = e.what();
      kind = "operation";
    } catch (const std::bad_alloc&) {
      failure = "out of memory";
      kind = "operation";
    } catch (const std::exception& e) {
      failure = e.what();
      kind = "operation";
    }
    if (!failure.empty()) {
      for (const std::string& m : todo)
        if (!emitted.count(m)) emit(m, json{{"error", failure}, {"error_kind", kind}});
    }
  }
  if (settings.progress)
    *settings.progress << "done: " << summary.records_written << " records in " << std::fixed
                       << std::setprecision(1) << elapsed() << " s\n";
  return summary;
}

}  // namespace hexrefine
