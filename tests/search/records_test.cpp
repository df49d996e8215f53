// results.jsonl records (records.hpp): bit-exact round trips of awkward
// doubles, one ParseError per bad-line case naming source:line and the key,
// and the truncated last line that only the tolerant loader accepts.
#include "touchdown/search/records.hpp"

#include <gtest/gtest.h>

#include <climits>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "touchdown/core/error.hpp"

namespace {

namespace ts = touchdown::search;
using touchdown::scenario::Violation;

ts::EvaluationRecord awkward_record() {
  ts::EvaluationRecord r;
  r.index = 0;
  r.generation = INT_MAX;
  r.scenario = "scenarios/000000.yaml";
  r.genes = {0.1 + 0.2, 1e-300, 0.0, 1.0, -0.0, std::numeric_limits<double>::denorm_min(), 1.0 / 3.0};
  r.fitness = 123456789012345678.0;
  r.evaluation.violation = Violation::TypeII;
  r.evaluation.message = "Type II: did not land in 60 s \"quoted\" \\ tab\t";
  r.evaluation.dtl = 1e21;
  r.evaluation.ttl = 60;
  r.evaluation.time_limit = 60;
  r.evaluation.landed = false;
  r.evaluation.collided = true;
  r.evaluation.reward_sum = 0.1 * 3;
  r.evaluation.frames = 1800;
  r.evaluation.flight_s = 59.999999999999993;
  r.evaluation.cells = {{INT_MIN, -1, 0}, {-1, 0, 0}, {0, 0, 0}, {0, 0, INT_MAX}};
  return r;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void expect_same(const ts::EvaluationRecord& a, const ts::EvaluationRecord& b) {
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.generation, b.generation);
  EXPECT_EQ(a.scenario, b.scenario);
  ASSERT_EQ(a.genes.size(), b.genes.size());
  for (std::size_t i = 0; i < a.genes.size(); ++i) EXPECT_TRUE(same_bits(a.genes[i], b.genes[i])) << i;
  EXPECT_TRUE(same_bits(a.fitness, b.fitness));
  const ts::Evaluation &x = a.evaluation, &y = b.evaluation;
  EXPECT_EQ(x.violation, y.violation);
  EXPECT_EQ(x.message, y.message);
  EXPECT_TRUE(same_bits(x.dtl, y.dtl));
  EXPECT_TRUE(same_bits(x.ttl, y.ttl));
  EXPECT_TRUE(same_bits(x.time_limit, y.time_limit));
  EXPECT_EQ(x.landed, y.landed);
  EXPECT_EQ(x.collided, y.collided);
  EXPECT_TRUE(same_bits(x.reward_sum, y.reward_sum));
  EXPECT_EQ(x.frames, y.frames);
  EXPECT_TRUE(same_bits(x.flight_s, y.flight_s));
  EXPECT_EQ(x.cells, y.cells);
}

TEST(Records, LineRoundTripIsBitExact) {
  const ts::EvaluationRecord r = awkward_record();
  const std::string line = record_line(r);
  EXPECT_EQ(line.find('\n'), std::string::npos);
  const ts::EvaluationRecord back = ts::parse_record_line(line, "results.jsonl", 1);
  expect_same(r, back);
  EXPECT_TRUE(std::signbit(back.genes[4]));  // -0.0 keeps its sign
  EXPECT_EQ(record_line(back), line);        // byte-stable
}

TEST(Records, KeyOrderIsFixed) {
  ts::EvaluationRecord r;
  r.scenario = "scenarios/000007.yaml";
  r.index = 7;
  r.generation = 1;
  r.genes = {0.5, 0.25};
  r.fitness = 1.5;
  r.evaluation.violation = Violation::TypeI;
  r.evaluation.message = "m";
  r.evaluation.dtl = 2.5;
  r.evaluation.ttl = 12;
  r.evaluation.cells = {{0, 1, 2}};
  EXPECT_EQ(record_line(r),
            "{\"index\":7,\"generation\":1,\"scenario\":\"scenarios/000007.yaml\",\"fitness\":1.5,\"genes\":[0.5,0.25],"
            "\"evaluation\":{\"violation\":\"I\",\"message\":\"m\",\"dtl\":2.5,\"ttl\":12,\"time_limit\":60,"
            "\"landed\":false,\"collided\":false,\"reward_sum\":0,\"frames\":0,\"flight_s\":0,\"cells\":[[0,1,2]]}}");
}

TEST(Records, EvaluationJsonRoundTrip) {
  const ts::Evaluation e = awkward_record().evaluation;
  const std::string text = ts::evaluation_json(e);
  const ts::Evaluation back = ts::parse_evaluation_json(text, "rank 1");
  EXPECT_EQ(ts::evaluation_json(back), text);
  EXPECT_TRUE(same_bits(back.flight_s, e.flight_s));
  try {
    (void)ts::parse_evaluation_json("{\"violation\":\"IV\"}", "rank 1");
    FAIL();
  } catch (const touchdown::ParseError& err) {
    EXPECT_EQ(std::string(err.what()).rfind("rank 1: violation: ", 0), 0u) << err.what();
  }
}

TEST(Records, NonFiniteValuesAreNotWritten) {
  ts::EvaluationRecord r = awkward_record();
  r.evaluation.dtl = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)ts::record_line(r), touchdown::InvalidArgument);
  r = awkward_record();
  r.fitness = std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)ts::record_line(r), touchdown::InvalidArgument);
}

// Replaces the first occurrence of `from` in the good line by `to`.
std::string good_line_with(const std::string& from, const std::string& to) {
  ts::EvaluationRecord r = awkward_record();
  r.generation = 3;
  std::string line = record_line(r);
  const auto at = line.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) line.replace(at, from.size(), to);
  return line;
}

TEST(Records, EveryBadLineNamesSourceLineAndKey) {
  struct Case {
    std::string line, expected;  // expected: the message after "results.jsonl:4: "
  };
  const std::vector<Case> cases = {
      {"", "empty line"},
      {"not json", "not a JSON object"},
      {"[1, 2]", "not a JSON object"},
      {"{\"index\":0", "not a JSON object"},
      {good_line_with("\"index\":0,", ""), "index: missing"},
      {good_line_with("\"index\":0", "\"index\":-1"), "index: -1 is below 0"},
      {good_line_with("\"index\":0", "\"index\":0.5"), "index: expected an integer, got a fraction"},
      {good_line_with("\"index\":0", "\"index\":\"0\""), "index: expected an integer, got string"},
      {good_line_with("\"index\":0", "\"index\":2147483648"), "index: integer out of range"},
      {good_line_with("\"index\":0", "\"index\":0,\"index\":0"), "index: repeated key"},
      {good_line_with("\"index\":0", "\"index\":0,\"extra\":1"), "extra: unknown key"},
      {good_line_with("\"generation\":3", "\"generation\":null"), "generation: expected an integer, got null"},
      {good_line_with("\"scenario\":\"scenarios/000000.yaml\"", "\"scenario\":\"\""), "scenario: empty"},
      {good_line_with("\"scenario\":\"scenarios/", "\"scenario\":\"/tmp/"),
       "scenario: must be relative to the results directory"},
      {good_line_with("\"fitness\":", "\"fitness\":1e999,\"x\":"), "not a JSON object"},
      {good_line_with("\"fitness\":", "\"fitness\":NaN,\"x\":"), "not a JSON object"},
      {good_line_with("\"fitness\":", "\"fitness\":true,\"x\":"), "fitness: expected a number, got boolean"},
      {good_line_with("\"genes\":[", "\"genes\":[1.5,"), "genes[0]: 1.5 outside [0, 1]"},
      {good_line_with("\"genes\":[", "\"genes\":[\"a\","), "genes[0]: expected a number, got string"},
      {good_line_with("\"genes\":[", "\"genes\":{\"a\":["), "not a JSON object"},
      {good_line_with("\"evaluation\":{", "\"evaluation\":[{"), "not a JSON object"},
      {good_line_with("\"evaluation\":{", "\"evaluation\":7,\"y\":{"), "evaluation: expected an object, got number"},
      {good_line_with("\"violation\":\"II\"", "\"violation\":\"IV\""), "evaluation.violation: expected one of"},
      {good_line_with("\"violation\":\"II\"", "\"violation\":\"TypeII\""), "evaluation.violation: expected one of"},
      {good_line_with("\"violation\":\"II\",", ""), "evaluation.violation: missing"},
      {good_line_with("\"dtl\":1e+21", "\"dtl\":-1"), "evaluation.dtl: -1 is below 0"},
      {good_line_with("\"ttl\":60", "\"ttl\":60,\"ttl\":60"), "evaluation.ttl: repeated key"},
      {good_line_with("\"time_limit\":60", "\"time_limit\":0"), "evaluation.time_limit: must be positive"},
      {good_line_with("\"landed\":false", "\"landed\":0"), "evaluation.landed: expected true or false, got number"},
      {good_line_with("\"frames\":1800", "\"frames\":-3"), "evaluation.frames: -3 is below 0"},
      {good_line_with("\"flight_s\":", "\"flight_s\":\"x\",\"z\":"), "evaluation.flight_s: expected a number"},
      {good_line_with("\"cells\":[", "\"cells\":[[1,2],"), "evaluation.cells[0]: expected a triple of integers"},
      {good_line_with("\"cells\":[", "\"cells\":[[1,2,0.5],"), "evaluation.cells[0]: expected an integer"},
      {good_line_with("\"cells\":[", "\"cells\":[[9,9,9],"), "evaluation.cells[1]: cells must be sorted and unique"},
      {good_line_with("\"cells\":[", "\"cells\":7,\"c\":["), "evaluation.cells: expected an array, got number"},
      {good_line_with("\"flight_s\"", "\"wind\":1,\"flight_s\""), "evaluation.wind: unknown key"},
  };
  for (const Case& c : cases) {
    try {
      (void)ts::parse_record_line(c.line, "results.jsonl", 4);
      ADD_FAILURE() << "accepted: " << c.line;
    } catch (const touchdown::ParseError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("results.jsonl:4: " + c.expected, 0), 0u) << what << "\n  line: " << c.line;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

class RecordsFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("touchdown_records_test_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::filesystem::path write(const std::string& text) {
    const auto path = dir_ / "results.jsonl";
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }

  static std::string line(int index) {
    ts::EvaluationRecord r = awkward_record();
    r.index = index;
    return ts::record_line(r);
  }

  std::filesystem::path dir_;
};

TEST_F(RecordsFile, LoadsEveryLineInOrder) {
  const auto path = write(line(0) + "\n" + line(1) + "\n" + line(2) + "\n");
  const auto records = ts::load_records(path);
  ASSERT_EQ(records.size(), 3u);
  EXPECT_EQ(records[2].index, 2);
  const ts::LoadedRecords tolerant = ts::load_records_tolerant(path);
  EXPECT_EQ(tolerant.records.size(), 3u);
  EXPECT_FALSE(tolerant.truncated_tail);
  EXPECT_TRUE(ts::load_records(write("")).empty());
}

TEST_F(RecordsFile, TruncatedTailOnlyTheTolerantLoaderAccepts) {
  const std::string whole = line(0) + "\n" + line(1) + "\n";
  for (const std::string& tail : {line(2).substr(0, 40), line(2)}) {
    const auto path = write(whole + tail);
    try {
      (void)ts::load_records(path);
      ADD_FAILURE() << "accepted a truncated tail";
    } catch (const touchdown::ParseError& e) {
      EXPECT_NE(std::string(e.what()).find("results.jsonl:3: truncated last line"), std::string::npos) << e.what();
    }
    const ts::LoadedRecords loaded = ts::load_records_tolerant(path);
    EXPECT_TRUE(loaded.truncated_tail);
    EXPECT_EQ(loaded.records.size(), 2u);
  }
  // A broken line that is not the last is an error for both loaders.
  const auto path = write(line(0) + "\n" + line(1).substr(0, 40) + "\n" + line(2) + "\n");
  EXPECT_THROW((void)ts::load_records_tolerant(path), touchdown::ParseError);
}

TEST_F(RecordsFile, IndexMustCountAndGenesKeepTheirLength) {
  try {
    (void)ts::load_records(write(line(0) + "\n" + line(2) + "\n"));
    FAIL();
  } catch (const touchdown::ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("results.jsonl:2: index: 2, expected 1"), std::string::npos) << e.what();
  }
  ts::EvaluationRecord shorter = awkward_record();
  shorter.index = 1;
  shorter.genes.pop_back();
  try {
    (void)ts::load_records(write(line(0) + "\n" + ts::record_line(shorter) + "\n"));
    FAIL();
  } catch (const touchdown::ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("results.jsonl:2: genes: 6 values, the first record has 7"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW((void)ts::load_records(dir_ / "missing.jsonl"), touchdown::IoError);
}

}  // namespace
