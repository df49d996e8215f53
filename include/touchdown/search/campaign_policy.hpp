#pragma once
/// \file
/// The DQN that drives an rlaga campaign's `external` objects, as
/// `landing_fuzz campaign` and `compare` choose it — a library function, so
/// that a C++ caller of run_search() gets the same weights and the same id
/// in campaign.json (which --resume checks) without the app.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "touchdown/search/dqn.hpp"

namespace touchdown::search {

/// The weights file a results directory keeps (docs/formats.md).
inline constexpr const char* kWeightsFile = "dqn_weights.txt";

/// "fnv1a64:<hex>" of weights_text(network): what campaign.json's
/// `weights` records, so that a campaign resumes only with its own weights.
std::string weights_id(const QNetwork& network);

struct CampaignPolicy {
  std::shared_ptr<const QNetwork> network;
  std::string id;        ///< weights_id(*network)
  bool trained = false;  ///< pre-trained now (neither loaded from a file nor from the directory)
};

/// `weights` when not empty (a weights file), else `dir`/dqn_weights.txt
/// when `resume` and it exists, else pre-trained now: train_dqn() with the
/// default options for `episodes` surrogate episodes from `seed`
/// (deterministic; `on_train` is called just before, for a message).
/// Throws what load_weights throws for a bad file.
CampaignPolicy campaign_policy(const std::filesystem::path& weights, const std::filesystem::path& dir, bool resume,
                               int episodes, std::uint64_t seed, const std::function<void()>& on_train = {});

/// Writes the weights into `dir`/dqn_weights.txt unless it exists (atomically).
void keep_weights(const QNetwork& network, const std::filesystem::path& dir);

}  // namespace touchdown::search
