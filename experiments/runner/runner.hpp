#pragma once
/// \file
/// The experiment runner: reads a case file (JSON), runs every (case, method) pair through an
/// executor and logs one JSON Lines record per pair. The runner's own logic (schema, record keys,
/// JSONL append/resume, shards, merge, sha256, machine facts) lives here and does not depend on
/// the refiners; case_execute (runner_execute.cpp) is the executor that builds the meshes, runs
/// the refiners and measures their outputs.
///
/// Case file schema (documented for users in results/README.md):
///   {"cases": [{"name": "G-1",
///               "mesh": {"generate": "brick", "dims": [10,10,10], "size": [1,1,1]} | {"file":
///               "m.mesh"}, "select": ["boundary:-1,0,0", ...], "methods": ["selective", "sheet"],
///               "passes": 1, "smooth": false, "save_mesh": false,
///               "options": {"ranking": true, "propagation": true, "ebe_only": false,
///                           "buffer": false, "allow_inverted": false,
///                           "placement": "optimized" | "trilinear"},
///               "expect": "refused" | {"selective": "refused"},  // optional, see RunCase
///               "tags": {...}}],           // optional, copied into every record
///    "output": "path.jsonl"}
/// Relative paths (mesh files, output) are relative to the case file's folder.

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "algorithms/refiners/refiner.hpp"

namespace hexrefine {

/// One case of a case file. `mesh` is the validated "mesh" object with "file" made absolute.
struct RunCase {
  int index = 0;  ///< position in the case file, 0-based (records are sorted by it)
  std::string name;
  nlohmann::json mesh;
  std::vector<std::string> select;        ///< selection specs, "hexes:FILE" made absolute
  std::vector<std::string> select_given;  ///< the specs as written (stamped on records)
  std::vector<std::string> methods;       ///< each "selective" or "sheet", no repeats
  RefineOptions options;                  ///< passes and the "options" object
  bool smooth = false;
  /// The case's pipeline options by the keys of algorithms/pipeline/pipeline_options_table.hpp
  /// ("passes", "smooth" and the "options" object), checked: case_execute sets its
  /// PipelineOptions from them; `options` and `smooth` are what they give (the record's key).
  nlohmann::json settings = nlohmann::json::object();
  bool save_mesh =
      false;  ///< write each refined mesh as .vtu (for experiments/studies/render_mesh.py)
  /// Set by run_plan_execute when save_mesh: the folder "<output stem>.meshes" beside the output.
  std::string save_mesh_dir;
  nlohmann::json tags = nlohmann::json::object();
  /// Methods this case expects to refuse ("expect": "refused" for all of them, or {"METHOD":
  /// "refused"}), e.g. the thesis suite's H-3 with the thesis' trilinear positions, where a
  /// template child inverts in a distorted parent. Their records carry "expect": "refused"; a
  /// refusal of theirs (error_kind "operation") is counted as expected, not as an error.
  std::vector<std::string> refusals_expected;
};

/// A parsed case file.
struct RunPlan {
  std::string source;  ///< the case file's path ("" for a plan built in memory)
  std::vector<RunCase> cases;
  std::string output;  ///< JSONL path, absolute or relative to the working directory
};

/// Validates a case file's JSON and builds the plan. `file` names the source in messages and
/// `base_dir` resolves relative paths. Throws InputError "FILE: JSON-PATH: what was expected"
/// (e.g. "cases.json: /cases/2/passes: expected an integer >= 1"). Unknown keys are errors too,
/// so a misspelt option is not silently ignored. Case names must be unique.
RunPlan run_plan_parse(const nlohmann::json& root, const std::string& file,
                       const std::string& base_dir);

/// The bytes of the file at `path`; InputError naming it if it cannot be read.
std::string run_file_read(const std::string& path);

/// Reads and parses a case file (syntax errors: InputError with the file, line and column).
RunPlan run_plan_read(const std::string& path);

/// The options of a record as JSON: every RefineOptions field but threads (the output does not
/// depend on it) plus "smooth", defaults filled in, so {} and {"ranking": true} give the same
/// object (and the same record key).
nlohmann::json run_options_to_json(const RefineOptions& options, bool smooth);

/// The key that identifies a record: case name, method and the dumped options object
/// (nlohmann::json objects are sorted by key, so the dump is canonical).
std::string run_record_key(const std::string& case_name, const std::string& method,
                           const nlohmann::json& options);

/// run_record_key of a record read back from a file; InputError if a key field is missing.
std::string run_record_key(const nlohmann::json& record);

/// Records of a JSON Lines file. A last line without its final newline (what a killed writer
/// leaves, since jsonl_append writes the newline last) is dropped, even if it parses, and
/// reported in `truncated_tail`; any other bad line is an InputError naming the file and line.
/// A missing file gives no records.
struct JsonlContent {
  std::vector<nlohmann::json> records;
  bool truncated_tail = false;
  std::string valid_text;  ///< the file's text up to the end of the last good line
};
JsonlContent jsonl_read(const std::string& path);

/// Appends one record as one line and flushes it to the OS before returning, so a killed run
/// loses no finished record. (The log is append-only by design; it is the one file not written
/// through atomic_file.hpp: a partial last line is repaired by jsonl_read / run --resume.)
void jsonl_append(const std::string& path, const nlohmann::json& record);

/// "K/N" -> {K-1, N}: shards are 1-based on the command line (K in 1..N, matching Slurm's
/// --array=1-N); case i (0-based) belongs to shard i % N. InputError for anything else.
std::pair<int, int> run_shard_parse(const std::string& text);

/// True if case `case_index` belongs to 0-based shard `shard` of `count`.
inline bool run_case_in_shard(int case_index, int shard, int count) {
  return count <= 1 || case_index % count == shard;
}

/// "out.jsonl" -> "out.shard-K-of-N.jsonl" (K 1-based): each shard writes its own file.
std::string run_shard_output(const std::string& output, int shard, int count);

/// Joins records: one per key (a later file's record replaces an earlier one, so a rerun
/// supersedes), sorted by (case_index, method_index) and, for ties, by key.
std::vector<nlohmann::json> run_records_merge(
    const std::vector<std::vector<nlohmann::json>>& inputs);

/// Writes records as JSON Lines atomically (mesh/atomic_file.hpp).
void jsonl_write(const std::string& path, const std::vector<nlohmann::json>& records);

/// SHA-256 (FIPS 180-4) of bytes, as 64 lowercase hex digits.
std::string sha256_hex(std::string_view data);

/// SHA-256 of a file's bytes; InputError naming the file if it cannot be read.
std::string sha256_file(const std::string& path);

/// Facts stamped on every record.
struct RunEnvironment {
  std::string commit = "unknown";  ///< `git rev-parse HEAD` in the source dir
  bool commit_dirty = false;       ///< tracked files differ from that commit
  std::string cpu = "unknown";     ///< "model name" of /proc/cpuinfo
  int cores = 0;                   ///< std::thread::hardware_concurrency()
  std::string build_type;          ///< "release" (NDEBUG) or "debug"
};
RunEnvironment run_environment_detect();

/// Current UTC time as "YYYY-MM-DDTHH:MM:SSZ".
std::string run_timestamp_utc();

/// Called once per case with the case and the methods still to run (resume leaves out the
/// finished ones); must call emit(method, fields) once per method, in order, as soon as that
/// method is done. `fields` holds the measured fields of the record (or "error"); the runner adds
/// the identification and environment fields. An exception escaping the executor is turned into
/// error records for the methods not yet emitted.
using RunEmit = std::function<void(const std::string& method, nlohmann::json fields)>;
using RunExecutor = std::function<void(const RunCase& c, const std::vector<std::string>& methods,
                                       const RunEmit& emit)>;

struct RunSettings {
  bool resume = false;
  bool quiet = false;
  int shard = 0;  ///< 0-based
  int shard_count = 1;
  std::string output;                ///< overrides plan.output when not empty
  std::ostream* progress = nullptr;  ///< where progress goes (nullptr: none)
  RunEnvironment environment;
};

struct RunSummary {
  int64_t records_written = 0;
  int64_t records_skipped = 0;  ///< present already (resume)
  int64_t errors = 0;           ///< records written with "error", expected refusals left out
  /// Records with "error" (error_kind "operation") of a method its case expects to refuse.
  int64_t refusals_expected = 0;
  /// Records of a method its case expects to refuse that were refined all the same.
  int64_t refusals_missing = 0;
  std::string output;
};

/// "N records (S already present, R refused (expected), E with an error)", plus ", M expected to
/// be refused but refined" when M > 0: the counts of the summary line of `run` and `reproduce`.
std::string run_summary_counts(const RunSummary& summary);

/// Runs the cases of `plan` in this shard through `execute` and appends a record per
/// (case, method). Without resume the output starts empty; with resume, records whose key is
/// present are skipped and a truncated last line is cut off first.
RunSummary run_plan_execute(const RunPlan& plan, const RunSettings& settings,
                            const RunExecutor& execute);

/// The real executor: builds or reads the mesh, then runs each method through the refinement
/// pipeline (algorithms/pipeline/pipeline.hpp); the record is its report plus the input's
/// description, wall and CPU seconds, and with save_mesh the file
/// save_mesh_dir/run_mesh_file_name(case, method) (record: "mesh_file"). A refusal (OperationError)
/// is a record with "error".
void case_execute(const RunCase& c, const std::vector<std::string>& methods, const RunEmit& emit);

/// "G-3/n=20", "selective" -> "G-3_n=20.selective.vtu": case names may hold '/'.
std::string run_mesh_file_name(const std::string& case_name, const std::string& method);

/// The source tree (HEXREFINE_SOURCE_DIR) and the shared folder beside it (its ../shared).
std::string run_source_dir();
std::string run_shared_dir();

}  // namespace hexrefine
