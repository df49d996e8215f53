// The DQN (dqn.hpp): backpropagation against finite differences, Adam
// against a hand computation, learning a gridworld's optimal policy, the
// weights file, and the world policy (object_policy.hpp).
#include "touchdown/search/dqn.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/scenario/world.hpp"
#include "touchdown/search/campaign_policy.hpp"
#include "touchdown/search/object_policy.hpp"
#include "touchdown/search/surrogate.hpp"

namespace touchdown::search {
namespace {

namespace fs = std::filesystem;
using scenario::ObjectAction;

TEST(DqnAction, FollowsEq4Order) {
  EXPECT_EQ(dqn_action(0), ObjectAction::Up);
  EXPECT_EQ(dqn_action(1), ObjectAction::Down);
  EXPECT_EQ(dqn_action(2), ObjectAction::Left);
  EXPECT_EQ(dqn_action(3), ObjectAction::Right);
  EXPECT_EQ(dqn_action(4), ObjectAction::Stay);
  EXPECT_THROW((void)dqn_action(5), InvalidArgument);
  EXPECT_THROW((void)dqn_action(-1), InvalidArgument);
}

TEST(QNetwork, LayoutAndTies) {
  QNetwork net(24);
  EXPECT_EQ(net.parameter_count(), 24 * 4 + 24 + 24 * 24 + 24 + 5 * 24 + 5);
  EXPECT_EQ(net.greedy({1, 2, 3, 4}), 0);  // all zero: ties go to the lowest index
  // Output bias b3 is the last five parameters: make R (3) and S (4) tie.
  auto p = net.parameters();
  p[p.size() - 2] = 1.0;
  p[p.size() - 1] = 1.0;
  net.set_parameters(p);
  EXPECT_EQ(net.greedy({1, 2, 3, 4}), 3);
  EXPECT_THROW(net.set_parameters(std::vector<double>(3)), InvalidArgument);
  EXPECT_THROW(QNetwork(0), InvalidArgument);
  EXPECT_THROW(QNetwork(kDqnMaxHidden + 1), InvalidArgument);
}

TEST(QNetwork, GradientMatchesCentralDifferencesForEveryParameter) {
  Rng rng(11);
  QNetwork net(24);
  net.initialise(rng);
  // Non-zero biases so that no unit sits on its ReLU kink by construction.
  auto p = net.parameters();
  for (double& v : p) v += rng.uniform(-0.05, 0.05);
  net.set_parameters(p);
  const DqnState s{3.1, -2.4, 6.5, 1.2};
  for (int action = 0; action < kDqnActions; ++action) {
    const double target = 4.0 - action;
    std::vector<double> grad;
    const double loss = net.gradient(s, action, target, grad);
    const double q = net.q_values(s)[static_cast<std::size_t>(action)];
    EXPECT_DOUBLE_EQ(loss, 0.5 * (q - target) * (q - target));
    ASSERT_EQ(grad.size(), p.size());
    int nonzero = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const double h = 1e-5;
      QNetwork plus = net, minus = net;
      auto pp = p, pm = p;
      pp[i] += h;
      pm[i] -= h;
      plus.set_parameters(pp);
      minus.set_parameters(pm);
      std::vector<double> unused;
      const double fd =
          (plus.gradient(s, action, target, unused) - minus.gradient(s, action, target, unused)) / (2 * h);
      // Relative error, with a floor of 1e-3 on the scale for (near-)zero
      // gradients (dead units: both exactly 0).
      const double scale = std::max({std::abs(fd), std::abs(grad[i]), 1e-3});
      EXPECT_LT(std::abs(fd - grad[i]) / scale, 1e-6) << "parameter " << i << " action " << action;
      if (grad[i] != 0) ++nonzero;
    }
    EXPECT_GT(nonzero, 100);  // the test exercised the hidden layers, not only b3
  }
}

TEST(Adam, TwoStepsMatchAHandComputation) {
  std::vector<double> theta{1.0, -2.0};
  Adam adam(2, 0.1);  // β1 0.9, β2 0.999, ε 1e-8
  adam.step(theta, std::vector<double>{0.5, -0.1});
  // t = 1: m̂ = g, v̂ = g², so θ −= lr g / (|g| + ε).
  EXPECT_DOUBLE_EQ(theta[0], 1.0 - 0.1 * 0.5 / (0.5 + 1e-8));
  EXPECT_DOUBLE_EQ(theta[1], -2.0 + 0.1 * 0.1 / (0.1 + 1e-8));
  const double a0 = theta[0];
  adam.step(theta, std::vector<double>{0.2, 0.3});
  // t = 2 for parameter 0: m = 0.9·0.05 + 0.1·0.2, v = 0.999·0.00025 + 0.001·0.04.
  const double m = 0.9 * 0.05 + 0.1 * 0.2, v = 0.999 * 0.00025 + 0.001 * 0.04;
  const double mhat = m / (1 - 0.9 * 0.9), vhat = v / (1 - 0.999 * 0.999);
  EXPECT_NEAR(theta[0], a0 - 0.1 * mhat / (std::sqrt(vhat) + 1e-8), 1e-15);
  EXPECT_EQ(adam.steps(), 2);
}

TEST(DqnOptions, ValidatesAndDecaysEpsilonPerEpisode) {
  DqnOptions o;
  std::string why;
  EXPECT_TRUE(o.validate(&why)) << why;
  EXPECT_DOUBLE_EQ(o.epsilon(0), 0.99);
  EXPECT_DOUBLE_EQ(o.epsilon(1), 0.99 * 0.995);
  EXPECT_DOUBLE_EQ(o.epsilon(2000), 0.01);
  o.batch = 0;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_EQ(why.rfind("batch:", 0), 0u);
  o = {};
  o.gamma = 1.0;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_EQ(why.rfind("gamma:", 0), 0u);
}

// A 5 × 5 gridworld with the goal in the middle (reward 1, episode over);
// every other step gives 0. Cells 2.5 m apart; state (x, y, 0, 0).
struct Grid {
  static constexpr int kHalf = 2;
  static constexpr double kCell = 2.5;
  static DqnState state(int x, int y) { return {x * kCell, y * kCell, 0, 0}; }
  static std::pair<int, int> move(int x, int y, int a) {
    if (a == 0) ++y;
    if (a == 1) --y;
    if (a == 2) --x;
    if (a == 3) ++x;
    return {std::clamp(x, -kHalf, kHalf), std::clamp(y, -kHalf, kHalf)};
  }
};

TEST(Dqn, LearnsTheGridworldsOptimalPolicyInEveryState) {
  DqnOptions o;
  o.gamma = 0.9;
  o.target_update = 50;
  Rng rng(5);
  Dqn dqn(o, rng);
  for (int episode = 0; episode < 400; ++episode) {
    int x = 0, y = 0;
    while (x == 0 && y == 0) {
      x = static_cast<int>(rng.uniform() * 5) - 2;
      y = static_cast<int>(rng.uniform() * 5) - 2;
    }
    const double eps = std::max(0.1, 1.0 - episode / 200.0);
    for (int t = 0; t < 20; ++t) {
      const int a = dqn.act(Grid::state(x, y), eps, rng);
      const auto [nx, ny] = Grid::move(x, y, a);
      const bool goal = nx == 0 && ny == 0;
      dqn.remember(Grid::state(x, y), a, goal ? 1.0 : 0.0, Grid::state(nx, ny), goal);
      dqn.train_step(rng);
      x = nx;
      y = ny;
      if (goal) break;
    }
  }
  // Optimal: any action that shortens the Manhattan distance to the goal.
  for (int x = -2; x <= 2; ++x) {
    for (int y = -2; y <= 2; ++y) {
      if (x == 0 && y == 0) continue;
      const int a = dqn.network().greedy(Grid::state(x, y));
      const auto [nx, ny] = Grid::move(x, y, a);
      EXPECT_EQ(std::abs(nx) + std::abs(ny), std::abs(x) + std::abs(y) - 1)
          << "cell (" << x << ", " << y << "): action " << a;
    }
  }
}

TEST(Dqn, TrainStepWaitsForABatchAndCopiesTheTargetNetwork) {
  DqnOptions o;
  o.batch = 4;
  o.replay_capacity = 4;
  o.target_update = 2;
  Rng rng(3);
  Dqn dqn(o, rng);
  EXPECT_EQ(dqn.network(), dqn.target_network());
  for (int i = 0; i < 3; ++i) dqn.remember({1, 0, 0, 0}, 3, 1.0, {2, 0, 0, 0}, true);
  EXPECT_EQ(dqn.train_step(rng), 0.0);
  EXPECT_EQ(dqn.train_steps(), 0);
  for (int i = 0; i < 3; ++i) dqn.remember({1, 0, 0, 0}, 3, 1.0, {2, 0, 0, 0}, true);
  EXPECT_EQ(dqn.replay_size(), 4);  // capacity: the oldest are dropped
  EXPECT_GT(dqn.train_step(rng), 0.0);
  EXPECT_FALSE(dqn.network() == dqn.target_network());
  dqn.train_step(rng);
  EXPECT_EQ(dqn.network(), dqn.target_network());  // copied after target_update steps
}

TEST(TrainDqn, SameSeedSameParameters) {
  SurrogateOptions env;
  const DqnTraining a = train_dqn({}, env, 12, 42);
  const DqnTraining b = train_dqn({}, env, 12, 42);
  const DqnTraining c = train_dqn({}, env, 12, 43);
  const auto pa = a.network.parameters(), pb = b.network.parameters();
  ASSERT_EQ(pa.size(), pb.size());
  EXPECT_EQ(std::memcmp(pa.data(), pb.data(), pa.size() * sizeof(double)), 0);
  EXPECT_EQ(a.episode_returns, b.episode_returns);
  EXPECT_NE(pa, c.network.parameters());
  int calls = 0;
  (void)train_dqn({}, env, 3, 1, [&](const Progress& p) {
    EXPECT_EQ(p.done, static_cast<std::size_t>(++calls));
    EXPECT_EQ(p.total, 3u);
    EXPECT_EQ(p.index, p.done - 1);
  });
  EXPECT_EQ(calls, 3);
}

class WeightsFile : public ::testing::Test {
 protected:
  test::TempDir tmp_;
  const fs::path& dir_ = tmp_.path();
  fs::path write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  // load_weights(file) throws ParseError with one line naming the file and `what`.
  void expect_rejected(const std::string& name, const std::string& text, const std::string& what) {
    const fs::path p = write(name, text);
    try {
      (void)load_weights(p);
      ADD_FAILURE() << name << " accepted";
    } catch (const ParseError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind(p.string() + ":", 0), 0u) << m;
      EXPECT_NE(m.find(what), std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
  }
  static QNetwork sample() {
    Rng rng(9);
    QNetwork net(6);
    net.initialise(rng);
    auto p = net.parameters();
    p[0] = -0.0;
    p[1] = std::numeric_limits<double>::denorm_min();
    p[2] = 0.1;
    p[3] = -1e300;
    net.set_parameters(p);
    return net;
  }
};

TEST_F(WeightsFile, RoundTripIsBitExact) {
  const QNetwork net = sample();
  const fs::path p = dir_ / "w.txt";
  save_weights(net, p);
  const QNetwork back = load_weights(p);
  EXPECT_EQ(back.hidden(), 6);
  const auto a = net.parameters(), b = back.parameters();
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
  EXPECT_TRUE(std::signbit(b[0]));
  EXPECT_EQ(weights_text(back), weights_text(net));
  EXPECT_EQ(weights_text(net).rfind("touchdown-dqn-weights 1\nhidden 6\nparameters 107\n", 0), 0u);
  // CRLF line ends read the same.
  std::string crlf;
  for (const char c : weights_text(net)) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  EXPECT_EQ(parse_weights(crlf, "crlf").parameters(), a);
}

TEST_F(WeightsFile, BadFilesThrowParseErrorNamingTheFile) {
  const std::string good = weights_text(sample());
  expect_rejected("truncated.txt", good.substr(0, good.size() / 2), "truncated");
  expect_rejected("no_end.txt", good.substr(0, good.rfind("end")), "truncated");
  expect_rejected("empty.txt", "", "not a DQN weights file");
  expect_rejected("garbage.txt", "\x01\x02garbage\xff\n", "not a DQN weights file");
  expect_rejected("json.txt", "{\"hidden\": 24}\n", "not a DQN weights file");
  std::string v2 = good;
  v2.replace(0, v2.find('\n'), "touchdown-dqn-weights 2");
  expect_rejected("v2.txt", v2, "version 2 not supported");
  std::string size = good;
  size.replace(size.find("parameters 107"), 14, "parameters 112");
  expect_rejected("size.txt", size, "parameters: 112 given, a network with hidden 6 has 107");
  std::string hidden = good;
  hidden.replace(hidden.find("hidden 6"), 8, "hidden 7");
  expect_rejected("hidden.txt", hidden, "parameters: 107 given, a network with hidden 7 has");
  std::string huge = good;
  huge.replace(huge.find("hidden 6"), 8, "hidden 100000");
  expect_rejected("huge.txt", huge, "hidden: must be an integer in 1..256");
  std::string nan = good;
  nan.replace(nan.find("\n0.1\n"), 5, "\nnan\n");
  expect_rejected("nan.txt", nan, "parameter 2: not finite");
  std::string word = good;
  word.replace(word.find("\n0.1\n"), 5, "\nzero\n");
  expect_rejected("word.txt", word, "parameter 2: not a number");
  expect_rejected("extra.txt", good + "1.0\n", "content after the 'end' line");
  std::string early = good;
  early.replace(early.find("\n0.1\n"), 5, "\nend\n");
  expect_rejected("early_end.txt", early, "'end' after 2 of 107 parameters");
  EXPECT_THROW((void)load_weights(dir_ / "missing.txt"), IoError);
}

TEST_F(WeightsFile, SaveIntoAMissingDirectoryLeavesNothing) {
  EXPECT_THROW(save_weights(sample(), dir_ / "no" / "w.txt"), IoError);
  EXPECT_FALSE(fs::exists(dir_ / "no"));
}

TEST(WeightsFuzzSeeds, ParseOrFailAsTheirNamesSay) {
  const fs::path dir = fs::path(TOUCHDOWN_SOURCE_DIR) / "tests/fuzz/seeds/dqn_weights";
  EXPECT_EQ(load_weights(dir / "hidden1.txt").hidden(), 1);
  const QNetwork exotic = load_weights(dir / "hidden3_exotic.txt");
  EXPECT_EQ(parse_weights(weights_text(exotic), "x").parameters(), exotic.parameters());
  for (const char* bad : {"truncated.txt", "version2.txt", "wrong_count.txt"})
    EXPECT_THROW((void)load_weights(dir / bad), ParseError) << bad;
}

// A network whose Q(L) = relu(object x / 10), Q(R) = relu(−object x / 10),
// the rest 0: it moves the object towards the marker's x, L when right of it.
std::shared_ptr<const QNetwork> towards_marker_x() {
  auto net = std::make_shared<QNetwork>(2);
  auto p = net->parameters();
  // W1 (2 × 4, column-major): unit 0 = x, unit 1 = −x (column 0 = object x).
  p[0] = 1.0;
  p[1] = -1.0;
  // b1 at 8..9; W2 (2 × 2) at 10..13: identity.
  p[10] = 1.0;
  p[13] = 1.0;
  // b2 at 14..15; W3 (5 × 2) at 16..25: Q(L) = unit 0, Q(R) = unit 1.
  p[16 + 2] = 1.0;      // row 2 (L), column 0
  p[16 + 5 + 3] = 1.0;  // row 3 (R), column 1
  net->set_parameters(p);
  return net;
}

scenario::Scenario one_external_person(double x) {
  scenario::Scenario s;
  s.marker.position = {1.0, 0.0};
  scenario::DynamicObject o;
  o.motion = scenario::MotionKind::External;
  o.position = {x, 0.0};
  o.speed = 1.0;
  s.dynamic_objects.push_back(o);
  scenario::DynamicObject other;  // scripted: not driven
  other.position = {5, 5};
  other.motion = scenario::MotionKind::Still;
  s.dynamic_objects.insert(s.dynamic_objects.begin(), other);
  return s;
}

TEST(ObjectPolicy, MovesExternalObjectsAsTheGreedyActionSays) {
  const auto net = towards_marker_x();
  EXPECT_EQ(net->greedy({2.0, 0, 0, 0}), 2);   // L
  EXPECT_EQ(net->greedy({-2.0, 0, 0, 0}), 3);  // R
  for (const double x0 : {4.0, -2.0}) {
    const scenario::Scenario sc = one_external_person(x0);
    scenario::World world(sc);
    ObjectPolicy policy(net, 0.1);
    std::vector<ObjectAction> actions(static_cast<std::size_t>(world.external_count()));
    ASSERT_EQ(actions.size(), 1u);
    for (int k = 0; k < 50; ++k) {  // 1 s
      policy(world, actions);
      world.step({}, actions);
    }
    const double x = world.dynamic_poses()[1].translation().x();
    // Towards the marker (x = 1) at 1 m/s for 1 s: 1 m, the state relative to the marker.
    EXPECT_NEAR(x, x0 > 1 ? x0 - 1.0 : x0 + 1.0, 0.05) << "start " << x0;
    EXPECT_NEAR(world.dynamic_poses()[1].translation().y(), 0.0, 1e-12);
    EXPECT_NEAR(world.dynamic_poses()[0].translation().x(), 5.0, 1e-12);  // the scripted one stays
  }
}

TEST(ObjectPolicy, HoldsTheActionBetweenDecisions) {
  // Decides every 1 s: starting 0.3 m right of the marker it keeps going
  // left for the whole second, past the marker.
  const scenario::Scenario sc = one_external_person(1.3);
  scenario::World world(sc);
  ObjectPolicy policy(towards_marker_x(), 1.0);
  std::vector<ObjectAction> actions(1);
  for (int k = 0; k < 45; ++k) {  // 0.9 s
    policy(world, actions);
    world.step({}, actions);
  }
  EXPECT_NEAR(world.dynamic_poses()[1].translation().x(), 1.3 - 0.9, 0.03);
  EXPECT_THROW(ObjectPolicy(nullptr), InvalidArgument);
  EXPECT_THROW(ObjectPolicy(towards_marker_x(), 0.0), InvalidArgument);
}

}  // namespace
}  // namespace touchdown::search

// ---- the campaign's DQN (campaign_policy.hpp) ----------------------------------------------

namespace touchdown::search {
namespace {

// The id is what campaigns kept in the repository recorded: they resume.
TEST(CampaignPolicy, TheIdOfKeptWeightsIsTheOneTheirCampaignRecorded) {
  const std::filesystem::path dir =
      std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "docs/results/causes/opencv-mls/ground/rlaga/seed-1";
  const CampaignPolicy p = campaign_policy("", dir, true, 20, 1);
  EXPECT_FALSE(p.trained);
  EXPECT_EQ(p.id, "fnv1a64:605fc88a6ca50fcc");
  EXPECT_NE(test::read_text(dir / "campaign.json").find("\"weights\": \"" + p.id + "\""), std::string::npos);
}

TEST(CampaignPolicy, PreTrainsDeterministicallyAndPrefersAFileThenTheDirectory) {
  const test::TempDir dir;
  int trained = 0;
  const CampaignPolicy a = campaign_policy("", dir.path(), true, 20, 7, [&] { ++trained; });
  const CampaignPolicy b = campaign_policy("", dir.path(), false, 20, 7);
  EXPECT_TRUE(a.trained);
  EXPECT_EQ(trained, 1);
  EXPECT_EQ(a.id, b.id);  // same seed, same weights
  EXPECT_NE(a.id, campaign_policy("", dir.path(), false, 20, 8).id);
  keep_weights(*a.network, dir.path());
  const CampaignPolicy resumed = campaign_policy("", dir.path(), true, 20, 8);  // the directory's, not seed 8's
  EXPECT_FALSE(resumed.trained);
  EXPECT_EQ(resumed.id, a.id);
  const CampaignPolicy file = campaign_policy(dir.path() / kWeightsFile, "", false, 20, 8);
  EXPECT_EQ(file.id, a.id);
}

}  // namespace
}  // namespace touchdown::search
