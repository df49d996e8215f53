#pragma once
/// \file
/// Campaigns across processes and machines with MPI (Open MPI): rank 0 runs
/// the search (run_search) with an MpiEvaluator; every other rank calls
/// serve() and evaluates its share of each batch until rank 0's evaluator
/// is destroyed. Scenario i of a batch runs on rank i mod size (rank 0
/// included), with `options.threads` threads on each rank; evaluations are
/// deterministic, so the results directory is the same for any number of
/// ranks and threads. Scenarios and evaluations travel as JSON text
/// (scenario::to_json, evaluation_json), which reads back bit-exact.
///
/// In library touchdown::search_mpi (links MPI); this header includes no
/// MPI header. MPI calls are made from the thread that constructed the
/// session only (MPI_THREAD_FUNNELED).
#include <memory>

#include "touchdown/search/search.hpp"

namespace touchdown::search {

/// MPI_Init_thread and MPI_Finalize around a process's work, when the
/// process was started by an MPI launcher (mpirun sets OMPI_COMM_WORLD_SIZE
/// or PMIX_RANK); otherwise nothing is initialised and active() is false
/// (rank 0 of 1).
class MpiSession {
 public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  [[nodiscard]] bool active() const { return active_; }
  [[nodiscard]] int rank() const { return rank_; }
  [[nodiscard]] int size() const { return size_; }
  /// Stops every rank (MPI_Abort) with `code`: for an error on one rank that
  /// the others cannot see.
  void abort(int code) const;

 private:
  bool active_ = false;
  int rank_ = 0, size_ = 1;
};

/// Adds `mpi` (an MpiEvaluator; needs an active session) to
/// evaluator_registry(). Once per process; later calls do nothing.
void register_mpi_evaluator();

class MpiEvaluator final : public Evaluator {
 public:
  /// Needs an active session; throws InvalidArgument for invalid options.
  explicit MpiEvaluator(EvaluatorOptions options);
  /// On rank 0: tells the other ranks to stop serving.
  ~MpiEvaluator() override;
  MpiEvaluator(const MpiEvaluator&) = delete;
  MpiEvaluator& operator=(const MpiEvaluator&) = delete;

  /// Rank 0 only. `on_done` sees rank 0's own runs as they finish and the
  /// other ranks' when their share arrives.
  std::vector<Evaluation> evaluate(const std::vector<scenario::Scenario>& scenarios,
                                   const std::function<void(std::size_t, const Evaluation&)>& on_done) override;
  [[nodiscard]] std::string system_name() const override { return local_.system_name(); }
  [[nodiscard]] bool coordinator() const override { return rank_ == 0; }
  /// Ranks other than 0: evaluates shares until rank 0 says stop.
  void serve() override;

 private:
  LocalEvaluator local_;
  int rank_ = 0, size_ = 1;
  bool stopped_ = false;
};

}  // namespace touchdown::search
