#pragma once
/// \file
/// The results directory's results.jsonl (docs/formats.md, "Violation
/// search results directory"): one JSON object per evaluated scenario, in
/// evaluation order, written as each evaluation finishes so that a killed
/// campaign can resume. The same text for the same record on every run and
/// machine: keys in a fixed order, doubles in their shortest text that reads
/// back to the same bits (a campaign's results file is byte-identical for
/// any number of threads and ranks). Also the Evaluation alone as JSON, which
/// the MPI evaluator ships between ranks.
///
/// Readers refuse, with a ParseError "source:line: key: what" (one line,
/// the key dotted as "evaluation.dtl" or "genes[3]"): a line that is not one
/// JSON object, a missing, unknown or repeated key, a value of the wrong
/// type, a number that is not finite or out of range (genes outside [0, 1],
/// negative distances, times, counts), a violation type other than none, I,
/// II, III, coverage cells that are not integer triples sorted and unique.
/// All functions are thread-safe (no shared state).
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/search/evaluation.hpp"

namespace touchdown::search {

/// One evaluated scenario: a line of the results directory's results.jsonl.
struct EvaluationRecord {
  int index = 0;              ///< evaluation order, 0, 1, 2, ... (line number - 1)
  int generation = 0;         ///< GA generation (0 = the seed pool); the random method: index / population
  std::string scenario;       ///< its file, relative to the results directory: "scenarios/000123.yaml"
  std::vector<double> genes;  ///< the normalised chromosome, each in [0, 1] (eq. 7)
  double fitness = 0;         ///< eq. 1 or eq. 6 (what the method ranked by)
  Evaluation evaluation;
};

/// One JSON object, no newline: keys index, generation, scenario, fitness,
/// genes, evaluation (as evaluation_json), in that order. Throws
/// InvalidArgument naming the key when a double is not finite (JSON has no
/// NaN; a record that cannot be read back is never written).
std::string record_line(const EvaluationRecord& r);

/// Parses one line of results.jsonl (without its newline). ParseError
/// "source:line_number: key: what" on anything record_line would not write.
EvaluationRecord parse_record_line(std::string_view line, std::string_view source, int line_number);

/// Every line of `results_jsonl` parsed. The line numbers must count: record
/// i has index i. Every record's genes have the same length as the first's.
/// A last line without its newline (a campaign killed while writing it) is a
/// ParseError "results.jsonl:N: truncated last line (no newline)": use
/// load_records_tolerant to resume from such a file. An empty file has no
/// records. IoError when the file cannot be read.
std::vector<EvaluationRecord> load_records(const std::filesystem::path& results_jsonl);

struct LoadedRecords {
  std::vector<EvaluationRecord> records;
  bool truncated_tail = false;  ///< an unterminated last line was dropped
};

/// As load_records, but an unterminated last line (whatever it holds) is
/// dropped instead of failing, for --resume: that evaluation is run again.
/// Every complete line must still parse.
LoadedRecords load_records_tolerant(const std::filesystem::path& results_jsonl);

/// The Evaluation alone as one JSON object, no newline: keys violation,
/// message, dtl, ttl, time_limit, landed, collided, reward_sum, frames,
/// flight_s, cells, in that order, then facts when recorded (issue 52;
/// docs/formats.md lists its keys; a reader takes a record without it, as
/// written before). InvalidArgument when a double is not finite.
std::string evaluation_json(const Evaluation& e);

/// Parses evaluation_json's text. ParseError "source: key: what".
Evaluation parse_evaluation_json(std::string_view text, std::string_view source);

}  // namespace touchdown::search
