// The lines that processes print once they listen, in one place, so that the launcher that
// waits for them and the processes that print them agree.
#pragma once

#include <string>

namespace auvrl::listening {

/// How the learner's first line begins, printed once it has subscribed to the actors'
/// experience (and restored a checkpoint when resuming).
inline const std::string kLearner = "auv_learner: listening: ";
/// How the logger's first line begins, printed once it has subscribed to every channel.
inline const std::string kLogger = "auv_logger: logging '";

}  // namespace auvrl::listening
