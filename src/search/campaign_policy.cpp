// The DQN of an rlaga campaign (campaign_policy.hpp).
#include "touchdown/search/campaign_policy.hpp"

#include <utility>

#include "core/hash.hpp"
#include "touchdown/search/surrogate.hpp"

namespace touchdown::search {

std::string weights_id(const QNetwork& network) {
  // FNV-1a, 64 bit, of the weights' text form.
  return detail::fnv1a64_id(detail::fnv1a64(weights_text(network)));
}

CampaignPolicy campaign_policy(const std::filesystem::path& weights, const std::filesystem::path& dir, bool resume,
                               int episodes, std::uint64_t seed, const std::function<void()>& on_train) {
  CampaignPolicy p;
  if (!weights.empty()) {
    p.network = std::make_shared<const QNetwork>(load_weights(weights));
  } else if (resume && std::filesystem::exists(dir / kWeightsFile)) {
    p.network = std::make_shared<const QNetwork>(load_weights(dir / kWeightsFile));
  } else {
    if (on_train) on_train();
    DqnTraining t = train_dqn(DqnOptions{}, SurrogateOptions{}, episodes, seed);
    p.network = std::make_shared<const QNetwork>(std::move(t.network));
    p.trained = true;
  }
  p.id = weights_id(*p.network);
  return p;
}

void keep_weights(const QNetwork& network, const std::filesystem::path& dir) {
  if (!std::filesystem::exists(dir / kWeightsFile)) save_weights(network, dir / kWeightsFile);
}

}  // namespace touchdown::search
