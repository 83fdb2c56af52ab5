// Choosing among fine-tuning candidates (tuning/candidate_selection.hpp): the candidates' seeds,
// the choice, and the robustness groups a policy passes against the PID at a validation seed and
// the way-points straight behind it reaches late.
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

CandidateScore score(int groups, int late) { return {groups, late, 100}; }

TEST(CandidateSelection, BehindPassesWithAtMostATenthLate) {
  EXPECT_TRUE(score(25, 0).behind_passes());
  EXPECT_TRUE(score(25, 10).behind_passes());
  EXPECT_FALSE(score(25, 11).behind_passes());
  EXPECT_EQ(score(24, 10).criteria_passing(), 25);
  EXPECT_EQ(score(24, 11).criteria_passing(), 24);
  // No way-points behind drawn: nothing late.
  EXPECT_TRUE((CandidateScore{20, 0, 0}).behind_passes());
}

TEST(CandidateSelection, TheMostCriteriaWinThenFewerLateThenTheEarliest) {
  EXPECT_EQ(choose_candidate({score(21, 0), score(25, 0), score(25, 0), score(24, 0)}), 1u);
  EXPECT_EQ(choose_candidate({score(3, 0)}), 0u);
  EXPECT_EQ(choose_candidate({score(20, 0), score(19, 0), score(20, 0)}), 0u);
  // Backing towards the way-points behind costs a criterion: 25 + 0 against 24 + 1.
  EXPECT_EQ(choose_candidate({score(25, 15), score(24, 6)}), 1u);
  // Level on criteria, the fewer late.
  EXPECT_EQ(choose_candidate({score(25, 6), score(25, 2), score(25, 2)}), 1u);
  EXPECT_EQ(choose_candidate({score(25, 30), score(25, 12)}), 1u);
  EXPECT_THROW(choose_candidate({}), std::invalid_argument);
}

TEST(CandidateSelection, TheMeanIsKeptUnlessTheChosenSearchPassesMoreCriteria) {
  EXPECT_TRUE(keep_mean(score(25, 0), score(25, 0)));  // level: the mean
  EXPECT_TRUE(keep_mean(score(25, 8), score(25, 0)));  // level on criteria, more late: still
  EXPECT_TRUE(keep_mean(score(24, 0), score(23, 0)));
  EXPECT_FALSE(keep_mean(score(23, 0), score(24, 0)));
  // The behind criterion counts: 24 + 0 against 24 + 1, and 25 + 0 against 24 + 1 is level.
  EXPECT_FALSE(keep_mean(score(24, 15), score(24, 2)));
  EXPECT_TRUE(keep_mean(score(24, 2), score(24, 15)));
  EXPECT_TRUE(keep_mean(score(25, 15), score(24, 2)));
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
  // The way-points straight behind: the committed policy reaches most of them no later than the
  // PID; one that never moves is late wherever the PID arrives.
  const CandidateScore committed = selector.score(trained);
  EXPECT_EQ(committed.groups_passing, passing);
  EXPECT_EQ(committed.behind_episodes, kBehindEpisodes);
  EXPECT_LT(committed.behind_late, kBehindEpisodes / 2);
  const CandidateScore idle = selector.score(untrained);
  EXPECT_GT(idle.behind_late, 90);
  EXPECT_FALSE(idle.behind_passes());
  EXPECT_EQ(selector.score(trained).behind_late, committed.behind_late);
}

}  // namespace
}  // namespace auvrl::tuning
