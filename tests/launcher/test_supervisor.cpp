// The Supervisor in process: a fake clock and fake processes stand in for time and children.
#include <gtest/gtest.h>

#include <csignal>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "agent_test_util.hpp"
#include "launcher/supervisor.hpp"
#include "tests/launcher/manual_clock.hpp"

namespace auvrl::launcher {
namespace {

/// What the test controls and observes of one fake process.
struct FakeState {
  int pid = 0;
  std::vector<std::string> argv;
  bool running = true;
  int status = 0;
  bool killed = false;
  double terminate_grace_s = -1;
  int terminate_order = -1;
};

class FakeProcess : public Process {
 public:
  FakeProcess(std::shared_ptr<FakeState> state, int* terminations)
      : state_(std::move(state)), terminations_(terminations) {}
  int pid() const override { return state_->pid; }
  bool running() override { return state_->running; }
  int wait_status() override { return state_->status; }
  void kill() override {
    state_->killed = true;
    state_->running = false;
    state_->status = SIGKILL;  // a wait status: killed by signal 9
  }
  void terminate(double grace_s) override {
    state_->terminate_grace_s = grace_s;
    state_->terminate_order = (*terminations_)++;
    state_->running = false;
  }

 private:
  std::shared_ptr<FakeState> state_;
  int* terminations_;
};

/// Hands out fake processes with pids 100, 101, ... and remembers each start.
class FakeStarter : public ProcessStarter {
 public:
  std::unique_ptr<Process> start(const std::vector<std::string>& argv,
                                 const std::string&) override {
    auto state = std::make_shared<FakeState>();
    state->pid = next_pid++;
    state->argv = argv;
    started.push_back(state);
    return std::make_unique<FakeProcess>(state, &terminations);
  }
  /// The newest process of the role whose argv[0] is name.
  std::shared_ptr<FakeState> newest(const std::string& name) const {
    for (auto it = started.rbegin(); it != started.rend(); ++it) {
      if ((*it)->argv.at(0) == name) return *it;
    }
    return nullptr;
  }
  int starts(const std::string& name) const {
    int n = 0;
    for (const auto& s : started) n += s->argv.at(0) == name ? 1 : 0;
    return n;
  }

  std::vector<std::shared_ptr<FakeState>> started;
  int next_pid = 100;
  int terminations = 0;
};

RoleSpec role(const std::string& name, RoleKind kind, int actor_id = -1) {
  RoleSpec spec;
  spec.name = name;
  spec.kind = kind;
  spec.argv = [name](std::size_t restarts) {
    return std::vector<std::string>{name, std::to_string(restarts)};
  };
  spec.log_path = "/logs/" + name + ".log";
  spec.actor_id = actor_id;
  return spec;
}

constexpr int kExit1 = 1 << 8;  // a wait status: exit code 1

class SupervisorTest : public ::testing::Test {
 protected:
  void make(SupervisorSettings settings) {
    supervisor = std::make_unique<Supervisor>(settings, clock, starter, out, false);
  }
  /// Advances the clock to t_s in passes of step_s (as the launcher's loop does).
  SupervisionOutcome run_until(double t_s, double step_s = 0.1) {
    SupervisionOutcome outcome;
    while (clock.t_s < t_s - 1e-9 && !outcome.stop) {
      clock.t_s = std::min(t_s, clock.t_s + step_s);
      outcome = supervisor->poll();
    }
    return outcome;
  }
  void crash(const std::string& name, int status = SIGKILL) {
    starter.newest(name)->running = false;
    starter.newest(name)->status = status;
  }

  ManualClock clock;
  FakeStarter starter;
  std::ostringstream out;
  std::unique_ptr<Supervisor> supervisor;
};

TEST_F(SupervisorTest, StartsEveryRoleInOrderWithTheHook) {
  make({});
  std::vector<std::string> started;
  supervisor->add(role("logger", RoleKind::kLogger));
  supervisor->add(role("sim0", RoleKind::kSim));
  supervisor->add(role("learner", RoleKind::kLearner));
  supervisor->on_start([&](const std::string& name, int pid) {
    started.push_back(name + ":" + std::to_string(pid));
  });
  supervisor->start_all();
  EXPECT_EQ(started, (std::vector<std::string>{"logger:100", "sim0:101", "learner:102"}));
  EXPECT_EQ(supervisor->pid("sim0"), 101);
  EXPECT_FALSE(supervisor->poll().stop);
  EXPECT_EQ(out.str(), "");
}

TEST_F(SupervisorTest, KilledProcessIsRestartedAfterADoublingBackOffCappedAt30s) {
  make({1000, 10000, 60});
  supervisor->add(role("sim0", RoleKind::kSim));
  supervisor->start_all();
  const std::vector<double> expected_s = {0.5, 1, 2, 4, 8, 16, 30, 30};
  const std::vector<std::string> shown = {"0.5", "1", "2", "4", "8", "16", "30", "30"};
  for (std::size_t i = 0; i < expected_s.size(); ++i) {
    crash("sim0");
    out.str("");
    supervisor->poll();
    EXPECT_EQ(out.str(), "auvrl train: sim0 ended (signal 9); restarting in " + shown[i] + " s\n");
    const double ended_s = clock.t_s;
    run_until(ended_s + expected_s[i] - 0.05, 0.01);
    EXPECT_EQ(starter.starts("sim0"), static_cast<int>(i) + 1) << "restarted too early, i=" << i;
    run_until(ended_s + expected_s[i] + 0.001, 0.01);
    EXPECT_EQ(starter.starts("sim0"), static_cast<int>(i) + 2) << "not restarted, i=" << i;
    EXPECT_NE(out.str().find("auvrl train: restarting sim0\n"), std::string::npos);
    // The restart count reaches the command line (actors reseed with it).
    EXPECT_EQ(starter.newest("sim0")->argv.at(1), std::to_string(i + 1));
  }
}

TEST_F(SupervisorTest, ExitCodeIsNamedAndATerminalLineBreakPrecedesItOnATerminal) {
  supervisor = std::make_unique<Supervisor>(SupervisorSettings{}, clock, starter, out, true);
  supervisor->add(role("logger", RoleKind::kLogger));
  supervisor->start_all();
  crash("logger", kExit1);
  supervisor->poll();
  EXPECT_EQ(out.str(), "\nauvrl train: logger ended (exit 1); restarting in 0.5 s\n");
}

TEST_F(SupervisorTest, HungProcessIsKilledAndRestarted) {
  make({5, 120, 60});
  supervisor->add(role("logger", RoleKind::kLogger));
  supervisor->add(role("sim0", RoleKind::kSim));
  supervisor->start_all();
  const int logger_pid = supervisor->pid("logger");
  const int sim_pid = supervisor->pid("sim0");
  supervisor->heard_from_pid(sim_pid);  // its first sign of life, at t = 0
  // The logger keeps talking; the simulator falls silent.
  while (clock.t_s < 60.0 - 1e-9) {
    clock.t_s += 0.5;
    supervisor->heard_from_pid(logger_pid);
    supervisor->poll();
  }
  EXPECT_FALSE(starter.newest("sim0")->killed) << out.str();
  clock.t_s = 60.5;
  supervisor->heard_from_pid(logger_pid);
  supervisor->poll();
  EXPECT_TRUE(starter.newest("sim0")->killed);
  EXPECT_NE(out.str().find("auvrl train: sim0 silent for 61 s (no heartbeat; hung?); killing it\n"),
            std::string::npos)
      << out.str();
  EXPECT_FALSE(starter.newest("logger")->killed);
  supervisor->poll();  // reaped: restarted like a crashed one
  EXPECT_NE(out.str().find("sim0 ended (signal 9); restarting in 0.5 s"), std::string::npos);
  run_until(61.2);
  EXPECT_EQ(starter.starts("sim0"), 2);
  // The new process is watched from its own first sign of life on: silence before it is fine.
  run_until(200, 0.5);
  EXPECT_EQ(starter.starts("sim0"), 2) << out.str();
}

TEST_F(SupervisorTest, ActorsAreWatchedByTheirEpisodeReports) {
  make({5, 120, 60});
  supervisor->add(role("logger", RoleKind::kLogger));
  supervisor->add(role("actor3", RoleKind::kActor, 3));
  supervisor->start_all();
  supervisor->heard_from_actor(3);
  // The actor's pid being heard does not count for it.
  while (clock.t_s < 61) {
    clock.t_s += 0.5;
    supervisor->heard_from_pid(supervisor->pid("logger"));
    supervisor->heard_from_pid(supervisor->pid("actor3"));
    supervisor->poll();
  }
  EXPECT_TRUE(starter.newest("actor3")->killed);
  EXPECT_NE(out.str().find("actor3 silent for"), std::string::npos) << out.str();
}

TEST_F(SupervisorTest, TimeTheSupervisorWasNotListeningDoesNotCount) {
  make({5, 120, 60});
  supervisor->add(role("logger", RoleKind::kLogger));
  supervisor->add(role("sim0", RoleKind::kSim));
  supervisor->start_all();
  supervisor->poll();
  supervisor->heard_from_pid(supervisor->pid("logger"));
  supervisor->heard_from_pid(supervisor->pid("sim0"));
  // The launcher itself stalls for 100 s (a long quick evaluation, CPU starvation).
  clock.t_s = 100;
  supervisor->poll();
  EXPECT_FALSE(starter.newest("sim0")->killed);
  EXPECT_FALSE(starter.newest("logger")->killed);
  EXPECT_EQ(out.str(), "");
  // Silence after the stall still counts: the logger talks, the simulator does not.
  while (clock.t_s < 161) {
    clock.t_s += 0.5;
    supervisor->heard_from_pid(supervisor->pid("logger"));
    supervisor->poll();
  }
  EXPECT_TRUE(starter.newest("sim0")->killed) << out.str();
}

TEST_F(SupervisorTest, NobodyIsKilledWhenNobodyWasHeardForHalfTheTimeout) {
  make({5, 120, 60});
  supervisor->add(role("logger", RoleKind::kLogger));
  supervisor->add(role("sim0", RoleKind::kSim));
  supervisor->start_all();
  supervisor->heard_from_pid(supervisor->pid("logger"));
  supervisor->heard_from_pid(supervisor->pid("sim0"));
  run_until(300, 0.5);  // everybody silent: the bus or the machine, not every process
  EXPECT_FALSE(starter.newest("sim0")->killed);
  EXPECT_FALSE(starter.newest("logger")->killed);
  EXPECT_EQ(out.str(), "");
}

TEST_F(SupervisorTest, SilenceBeforeTheFirstSignOfLifeAndTimeoutZeroAreNotWatched) {
  make({5, 120, 0});
  supervisor->add(role("logger", RoleKind::kLogger));
  supervisor->add(role("sim0", RoleKind::kSim));
  supervisor->start_all();
  supervisor->heard_from_pid(supervisor->pid("sim0"));
  while (clock.t_s < 300) {
    clock.t_s += 0.5;
    supervisor->heard_from_pid(supervisor->pid("logger"));
    supervisor->poll();
  }
  EXPECT_FALSE(starter.newest("sim0")->killed);
}

TEST_F(SupervisorTest, GivesUpAfterMaxRestartsWithinTheWindowNamingTheRole) {
  make({2, 120, 60});
  supervisor->add(role("sim0", RoleKind::kSim));
  supervisor->add(role("learner", RoleKind::kLearner));
  supervisor->start_all();
  for (int i = 0; i < 2; ++i) {
    crash("learner");
    EXPECT_FALSE(supervisor->poll().stop);
    run_until(clock.t_s + 5);
  }
  EXPECT_EQ(starter.starts("learner"), 3);
  crash("learner");
  const SupervisionOutcome outcome = supervisor->poll();
  EXPECT_TRUE(outcome.stop);
  EXPECT_EQ(outcome.exit_code, 1);
  EXPECT_EQ(outcome.stop_reason, "learner failed 3 times within 2m00s (see /logs/learner.log)");
}

TEST_F(SupervisorTest, RestartsOutsideTheWindowAreForgotten) {
  make({2, 120, 60});
  supervisor->add(role("sim0", RoleKind::kSim));
  supervisor->start_all();
  for (int i = 0; i < 6; ++i) {
    crash("sim0");
    EXPECT_FALSE(supervisor->poll().stop) << "crash " << i;
    run_until(clock.t_s + 70, 0.5);  // two restarts never fall within 120 s of a third
  }
  EXPECT_EQ(starter.starts("sim0"), 7);
  // Back-off follows the restarts within the window: never more than one before.
  EXPECT_EQ(out.str().find("restarting in 2 s"), std::string::npos) << out.str();
}

TEST_F(SupervisorTest, CleanExitsEndTheLearnerAndTheActorButRestartTheOthers) {
  make({});
  supervisor->add(role("sim0", RoleKind::kSim));
  supervisor->add(role("learner", RoleKind::kLearner));
  supervisor->add(role("actor0", RoleKind::kActor, 0));
  supervisor->start_all();
  crash("actor0", 0);
  EXPECT_FALSE(supervisor->poll().stop);
  crash("sim0", 0);
  EXPECT_FALSE(supervisor->poll().stop);
  EXPECT_NE(out.str().find("sim0 ended (exit 0); restarting in 0.5 s"), std::string::npos);
  run_until(5);
  EXPECT_EQ(starter.starts("sim0"), 2);
  EXPECT_EQ(starter.starts("actor0"), 1);
  crash("learner", 0);
  const SupervisionOutcome outcome = supervisor->poll();
  EXPECT_TRUE(outcome.stop);
  EXPECT_EQ(outcome.exit_code, 0);
  EXPECT_EQ(outcome.stop_reason, "the learner's schedule ended");
}

TEST_F(SupervisorTest, StopsByKindWithTheirGrace) {
  make({});
  supervisor->add(role("logger", RoleKind::kLogger));
  supervisor->add(role("sim0", RoleKind::kSim));
  supervisor->add(role("learner", RoleKind::kLearner));
  supervisor->add(role("actor0", RoleKind::kActor, 0));
  supervisor->add(role("actor1", RoleKind::kActor, 1));
  supervisor->start_all();
  supervisor->stop(RoleKind::kActor, 5);
  supervisor->stop(RoleKind::kLearner, 120);
  EXPECT_EQ(starter.newest("actor0")->terminate_order, 0);
  EXPECT_EQ(starter.newest("actor1")->terminate_order, 1);
  EXPECT_EQ(starter.newest("learner")->terminate_order, 2);
  EXPECT_EQ(starter.newest("learner")->terminate_grace_s, 120);
  EXPECT_EQ(starter.newest("sim0")->terminate_order, -1);
  EXPECT_EQ(starter.newest("logger")->terminate_order, -1);
}

/// A logger and a learner that print a line once they listen, and two actors that wait for it;
/// their logs in a scratch directory.
class ListeningTest : public SupervisorTest {
 protected:
  void add_roles() {
    for (const auto& [name, kind] :
         {std::pair{"logger", RoleKind::kLogger}, std::pair{"learner", RoleKind::kLearner}}) {
      RoleSpec spec = role(name, kind);
      spec.log_path = dir.path(std::string(name) + ".log");
      spec.listening_text = std::string(name) + ": listening: ";
      supervisor->add(spec);
    }
    for (int i = 0; i < 2; ++i) {
      RoleSpec actor = role("actor" + std::to_string(i), RoleKind::kActor, i);
      actor.starts_after_listeners = true;
      supervisor->add(actor);
    }
  }
  void print(const std::string& name, const std::string& text) {
    std::ofstream(dir.path(name + ".log"), std::ios::app) << text;
  }
  int actor_starts() const { return starter.starts("actor0") + starter.starts("actor1"); }
  /// After a logger crash at t < 0.5 s: it is restarted after its 0.5 s back-off, and the actors
  /// start only once the new logger says it listens.
  void expect_actors_wait_for_the_restarted_logger() {
    run_until(1);
    EXPECT_EQ(starter.starts("logger"), 2);
    EXPECT_EQ(actor_starts(), 0);
    print("logger", "logger: listening: every channel\n");
    run_until(1.2);
    EXPECT_EQ(actor_starts(), 2);
  }

  test_support::TempDir dir;
};

TEST_F(ListeningTest, ActorsStartOnceTheLearnerAndTheLoggerListen) {
  make({});
  add_roles();
  supervisor->start_all();
  EXPECT_EQ(starter.started.size(), 2u);
  EXPECT_EQ(supervisor->pid("actor0"), -1);
  run_until(1);
  print("logger", "logger: listening: every channel\n");
  run_until(2);
  EXPECT_EQ(actor_starts(), 0) << "the learner does not listen yet";
  print("learner", "learner: listen");  // a line half written
  run_until(3);
  EXPECT_EQ(actor_starts(), 0);
  print("learner", "ing: td3\n");
  supervisor->poll();
  EXPECT_EQ(starter.starts("actor0"), 1);
  EXPECT_EQ(starter.starts("actor1"), 1);
  EXPECT_EQ(starter.newest("actor1")->pid, 103) << "started in the order added";
  run_until(10);
  EXPECT_EQ(actor_starts(), 2) << "started once";
  EXPECT_EQ(out.str(), "");
  // A restarted actor does not wait again.
  crash("actor0");
  run_until(11);
  EXPECT_EQ(starter.starts("actor0"), 2);
}

TEST_F(ListeningTest, OnlyALineSinceTheLatestStartCounts) {
  make({});
  print("logger", "logger: listening: in a run before the resume\n");
  print("learner", "learner: listening: in a run before the resume\n");
  add_roles();
  supervisor->start_all();
  run_until(2);
  EXPECT_EQ(actor_starts(), 0);
  // A line that only contains the text is not the line.
  print("logger", "error: logger: listening: \n");
  print("learner", "learner: listening: now\n");
  run_until(3);
  EXPECT_EQ(actor_starts(), 0);
  print("logger", "logger: listening: now\n");
  run_until(4);
  EXPECT_EQ(actor_starts(), 2);
}

TEST_F(ListeningTest, ActorsStartAnywayAfterTheWaitSayingWhoDidNotListen) {
  SupervisorSettings settings;
  settings.listen_wait_s = 5;
  make(settings);
  add_roles();
  supervisor->start_all();
  print("learner", "learner: listening: td3\n");
  run_until(4.95, 0.05);
  EXPECT_EQ(actor_starts(), 0);
  EXPECT_EQ(out.str(), "");
  run_until(5.05, 0.05);
  EXPECT_EQ(actor_starts(), 2);
  EXPECT_EQ(out.str(),
            "auvrl train: logger not listening after 5 s (no line beginning \"logger: "
            "listening: \" in " +
                dir.path("logger.log") + "); starting actor0 and 1 more anyway\n");
}

TEST_F(ListeningTest, AListenerRestartedBeforeItListenedIsWaitedFor) {
  make({});
  add_roles();
  supervisor->start_all();
  print("learner", "learner: listening: td3\n");
  crash("logger");
  run_until(0.2);
  EXPECT_EQ(actor_starts(), 0);
  expect_actors_wait_for_the_restarted_logger();
}

TEST_F(ListeningTest, AListenerThatEndedAfterItListenedIsWaitedForAgain) {
  make({});
  add_roles();
  supervisor->start_all();
  print("logger", "logger: listening: every channel\n");
  run_until(0.2);
  crash("logger");
  print("learner", "learner: listening: td3\n");
  run_until(0.4);
  EXPECT_EQ(actor_starts(), 0) << "the logger ended after it listened";
  expect_actors_wait_for_the_restarted_logger();  // its earlier line does not count
}

TEST(SteadyClockTest, NeverGoesBack) {
  SteadyClock clock;
  const double a = clock.now_s();
  EXPECT_GE(clock.now_s(), a);
}

}  // namespace
}  // namespace auvrl::launcher
