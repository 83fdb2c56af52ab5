// Choosing among fine-tuning candidates (tuning/candidate_selection.hpp): the candidates' seeds,
// the choice, and the robustness groups a policy passes against the PID at a validation seed.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "agent_test_util.hpp"
#include "tuning/candidate_selection.hpp"
#include "tuning_test_util.hpp"

namespace auvrl::tuning {
namespace {

using test::committed_policy;
using test::fast_task;
using test_support::nessie;

TEST(CandidateSelection, TheFirstCandidateIsTheRunsOwnSeed) {
  EXPECT_EQ(candidate_seed(7, 0), 7u);
  EXPECT_EQ(candidate_seed(7, 2), 9u);
  EXPECT_THROW(candidate_seed(7, -1), std::invalid_argument);
}

TEST(CandidateSelection, TheMostGroupsWinTiesGoToTheEarliest) {
  EXPECT_EQ(choose_candidate({21, 25, 25, 24}), 1u);
  EXPECT_EQ(choose_candidate({3}), 0u);
  EXPECT_EQ(choose_candidate({20, 19, 20}), 0u);
  EXPECT_THROW(choose_candidate({}), std::invalid_argument);
}

TEST(SuiteSelector, RefusesTheEvaluationsOwnDraw) {
  try {
    SuiteSelector selector(nessie(), fast_task(), 1, 1);
    FAIL() << "seed 1 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("evaluation's own draw"), std::string::npos) << e.what();
  }
}

// Two episodes a group keep it quick; the count is the comparison's, and a policy that has
// learnt nothing passes fewer groups than the committed one.
TEST(SuiteSelector, CountsTheGroupsThePolicyPassesAgainstThePid) {
  const SuiteSelector selector(nessie(), fast_task(), 1234, 2);
  EXPECT_EQ(selector.groups(), 25);
  const nn::Mlp trained = committed_policy();
  int passing = 0;
  for (const eval::GroupComparison& c : selector.compare(trained)) passing += c.passes() ? 1 : 0;
  EXPECT_EQ(selector.groups_passing(trained), passing);
  EXPECT_GT(passing, 15);
  nn::Mlp untrained = trained;
  untrained.params().setZero();
  EXPECT_LT(selector.groups_passing(untrained), passing);
  // Deterministic: the same draws and the same policy give the same count.
  EXPECT_EQ(selector.groups_passing(trained), passing);
}

}  // namespace
}  // namespace auvrl::tuning
