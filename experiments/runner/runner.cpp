#include "experiments/runner/runner.hpp"

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

#include "algorithms/pipeline/pipeline.hpp"
#include "mesh/atomic_file.hpp"
#include "mesh/error.hpp"
#include "mesh/generators.hpp"

namespace hexrefine {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

}  // namespace

std::string run_file_read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw InputError(path + ": read failed");
  return ss.str();
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
  const std::string text = run_file_read(path);
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
  return sha256_hex(run_file_read(path));
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

std::string run_summary_counts(const RunSummary& s) {
  std::string out = std::to_string(s.records_written) + " records (" +
                    std::to_string(s.records_skipped) + " already present, " +
                    std::to_string(s.refusals_expected) + " refused (expected), " +
                    std::to_string(s.errors) + " with an error";
  if (s.refusals_missing > 0)
    out += ", " + std::to_string(s.refusals_missing) + " expected to be refused but refined";
  return out + ")";
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
      record["schema_version"] = pipeline_report_schema_version;
      const bool refusal_expected =
          std::find(c.refusals_expected.begin(), c.refusals_expected.end(), method) !=
          c.refusals_expected.end();
      if (refusal_expected) record["expect"] = "refused";
      for (auto& [k, v] : fields.items()) record[k] = std::move(v);
      if (!record.contains("error"))
        summary.refusals_missing += refusal_expected;
      else if (refusal_expected && record.value("error_kind", "") == "operation")
        ++summary.refusals_expected;
      else
        ++summary.errors;
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
