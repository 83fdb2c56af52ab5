// The run's key: made once in RUN/keys (private key owner-only), and every policy file of a
// directory signed with it, so that the run's public key verifies each and nothing else.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "child_process.hpp"
#include "common/signature.hpp"
#include "launcher/run_signing.hpp"

namespace {

using namespace auvrl;
namespace fs = std::filesystem;

TEST(RunSigning, TheRunsKeyIsMadeOnceAndSignsEveryPolicyItHolds) {
  const std::string run = test_support::make_temp_dir("auvrl_run_signing_");
  const std::string key = launcher::ensure_run_key(run);
  EXPECT_EQ(key, run + "/keys/run.key");
  struct stat st {};
  ASSERT_EQ(stat(key.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  const auto first_key = fs::file_size(key);
  EXPECT_EQ(launcher::ensure_run_key(run), key);  // kept, not made again
  EXPECT_EQ(fs::file_size(key), first_key);

  std::ofstream(run + "/policy.nn") << "last";
  std::ofstream(run + "/policy_finetuned.nn") << "tuned";
  std::ofstream(run + "/other.nn") << "not a run's policy";
  std::ostringstream out;
  const auto signed_files = launcher::sign_policies(run, key, out);
  EXPECT_EQ(signed_files.size(), 2u) << out.str();
  EXPECT_NO_THROW(signature::verify_file(run + "/policy.nn", run + "/keys/run.pub"));
  EXPECT_NO_THROW(signature::verify_file(run + "/policy_finetuned.nn", run + "/keys/run.pub"));
  EXPECT_FALSE(fs::exists(run + "/other.nn.sig"));
  EXPECT_NE(out.str().find("--trust-key"), std::string::npos);

  // A key that cannot be read costs the signatures, said, and nothing else.
  std::ostringstream failed;
  EXPECT_TRUE(launcher::sign_policies(run, run + "/missing.key", failed).empty());
  EXPECT_NE(failed.str().find("cannot sign"), std::string::npos);
  EXPECT_TRUE(fs::exists(run + "/policy.nn"));
}

}  // namespace
