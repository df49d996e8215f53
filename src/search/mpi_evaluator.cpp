// MPI evaluator and session (mpi_evaluator.hpp). Protocol per batch: rank 0
// broadcasts the batch (its size, then the scenarios' JSON texts joined by
// '\x1e'); each rank runs scenarios i with i mod size == rank; each worker
// sends its evaluations' JSON texts joined by '\x1e' to rank 0 (tag 1). A
// batch of size 0 means stop.
#include "touchdown/search/mpi_evaluator.hpp"

#include <mpi.h>

#include <cstdlib>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>

#include "touchdown/core/error.hpp"

namespace touchdown::search {

namespace {

constexpr char kSeparator = '\x1e';  // ASCII record separator: never in JSON text
constexpr int kResultTag = 1;

bool launched_by_mpi() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMIX_RANK") != nullptr ||
         std::getenv("PMI_RANK") != nullptr;
}

void check(int code, const char* what) {
  if (code != MPI_SUCCESS) throw std::runtime_error(std::string("MPI: ") + what + " failed");
}

std::vector<std::string> split_records(const std::string& text) {
  std::vector<std::string> out;
  if (text.empty()) return out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t end = text.find(kSeparator, start);
    out.push_back(text.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return out;
}

std::string join_records(const std::vector<std::string>& parts) {
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (i) out += kSeparator;
    out += parts[i];
  }
  return out;
}

void broadcast(std::string& text) {
  unsigned long long n = text.size();
  check(MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD), "broadcast of a batch's size");
  text.resize(n);
  if (n > 0) check(MPI_Bcast(text.data(), static_cast<int>(n), MPI_CHAR, 0, MPI_COMM_WORLD), "broadcast of a batch");
}

}  // namespace

MpiSession::MpiSession(int& argc, char**& argv) {
  if (!launched_by_mpi()) return;
  int provided = 0;
  check(MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
  active_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

MpiSession::~MpiSession() {
  if (active_) MPI_Finalize();
}

void MpiSession::abort(int code) const {
  if (active_) MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

MpiEvaluator::MpiEvaluator(EvaluatorOptions options) : local_(std::move(options)) {
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (!initialised) throw InvalidArgument("MPI evaluator: MPI is not initialised (start the program with mpirun)");
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

MpiEvaluator::~MpiEvaluator() {
  if (rank_ == 0 && !stopped_ && size_ > 1) {
    std::string stop;
    try {
      broadcast(stop);
    } catch (...) {  // NOLINT(bugprone-empty-catch): nothing more to do while stopping
    }
  }
}

std::vector<Evaluation> MpiEvaluator::evaluate(const std::vector<scenario::Scenario>& scenarios,
                                               const std::function<void(std::size_t, const Evaluation&)>& on_done) {
  if (rank_ != 0) throw InvalidArgument("MPI evaluator: evaluate() is rank 0's; the other ranks serve()");
  if (scenarios.empty()) return {};
  std::vector<std::string> texts;
  texts.reserve(scenarios.size());
  for (const auto& s : scenarios) texts.push_back(scenario::to_json(s));
  std::string batch = join_records(texts);
  if (size_ > 1) broadcast(batch);
  // Rank 0's own share.
  std::vector<scenario::Scenario> mine;
  std::vector<std::size_t> mine_index;
  for (std::size_t i = 0; i < scenarios.size(); i += static_cast<std::size_t>(size_)) {
    mine.push_back(scenarios[i]);
    mine_index.push_back(i);
  }
  std::vector<Evaluation> out(scenarios.size());
  const auto own = local_.evaluate(mine, [&](std::size_t k, const Evaluation& e) {
    if (on_done) on_done(mine_index[k], e);
  });
  for (std::size_t k = 0; k < own.size(); ++k) out[mine_index[k]] = own[k];
  // The others', rank by rank.
  for (int r = 1; r < size_; ++r) {
    MPI_Status status;
    check(MPI_Probe(r, kResultTag, MPI_COMM_WORLD, &status), "probe");
    int n = 0;
    MPI_Get_count(&status, MPI_CHAR, &n);
    std::string text(static_cast<std::size_t>(n), '\0');
    check(MPI_Recv(text.data(), n, MPI_CHAR, r, kResultTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "receive");
    if (!text.empty() && text.front() == '!')
      throw std::runtime_error("MPI rank " + std::to_string(r) + ": " + text.substr(1));
    const std::vector<std::string> parts = split_records(text);
    std::size_t k = 0;
    for (std::size_t i = static_cast<std::size_t>(r); i < scenarios.size(); i += static_cast<std::size_t>(size_), ++k) {
      if (k >= parts.size()) throw std::runtime_error("MPI rank " + std::to_string(r) + " sent too few evaluations");
      out[i] = parse_evaluation_json(parts[k], "MPI rank " + std::to_string(r));
      if (on_done) on_done(i, out[i]);
    }
  }
  return out;
}

void register_mpi_evaluator() {
  static std::once_flag once;
  std::call_once(once, [] {
    evaluator_registry().add("mpi", "the scenarios of a batch spread over the MPI ranks (each with worker threads)",
                             [](const EvaluatorOptions& o) { return std::make_unique<MpiEvaluator>(o); });
  });
}

void MpiEvaluator::serve() {
  if (rank_ == 0) throw InvalidArgument("MPI evaluator: rank 0 runs the search; serve() is for the other ranks");
  for (;;) {
    std::string batch;
    broadcast(batch);
    if (batch.empty()) break;
    std::string reply;
    try {
      const std::vector<std::string> texts = split_records(batch);
      std::vector<scenario::Scenario> mine;
      for (std::size_t i = static_cast<std::size_t>(rank_); i < texts.size(); i += static_cast<std::size_t>(size_)) {
        mine.push_back(scenario::parse_scenario(texts[i], "MPI batch"));
      }
      std::vector<std::string> parts;
      for (const Evaluation& e : local_.evaluate(mine, {})) parts.push_back(evaluation_json(e));
      reply = join_records(parts);
    } catch (const std::exception& e) {
      reply = std::string("!") + e.what();
    }
    check(MPI_Send(reply.data(), static_cast<int>(reply.size()), MPI_CHAR, 0, kResultTag, MPI_COMM_WORLD), "send");
  }
  stopped_ = true;
}

}  // namespace touchdown::search
