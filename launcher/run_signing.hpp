// The run's key: `auvrl train` signs the policies it writes (common/signature.hpp), so that a
// vehicle's auv_controller --trust-key RUN/keys/run.pub flies them and nothing altered.
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace auvrl::launcher {

/// <run_dir>/keys/run.key (private, mode 0600) and run.pub, made if missing. Returns the
/// private key's path. Throws std::runtime_error naming the file that cannot be written.
std::string ensure_run_key(const std::string& run_dir);

/// Signs each of policy.nn, policy_best.nn, policy_average.nn and policy_finetuned.nn that `dir`
/// holds with the private key `key_path` (FILE.sig beside it) and says so on `out`. A failure is
/// reported on `out` and signs nothing more: the policies themselves are never touched. Returns
/// the policies signed.
std::vector<std::string> sign_policies(const std::string& dir, const std::string& key_path,
                                       std::ostream& out);

}  // namespace auvrl::launcher
