// Signed files (common/signature.hpp): a key pair written with the private key readable by its
// owner only and never overwritten; a signed file verifies; one altered byte, another key, no
// signature or a damaged one is refused, naming the file; OpenSSL's own command line verifies
// our signatures (an independent check of the format). And auv_controller's setup with a trust
// key refuses an unsigned or altered mission or policy before it reads them.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "agent/controller_process.hpp"
#include "child_process.hpp"
#include "common/signature.hpp"

namespace {

using namespace auvrl;
namespace fs = std::filesystem;

class Signature : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = test_support::make_temp_dir("auvrl_signature_");
    signature::generate_key_pair(dir + "/run.key", dir + "/run.pub");
    file = dir + "/policy.nn";
    std::ofstream(file, std::ios::binary) << "some policy bytes\n";
  }
  /// The message of what `f` throws ("" if nothing).
  template <class F>
  static std::string error_of(F f) {
    try {
      f();
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  }
  std::string dir;
  std::string file;
};

TEST_F(Signature, TheKeyPairIsPrivateAndNeverOverwritten) {
  struct stat st {};
  ASSERT_EQ(stat((dir + "/run.key").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  EXPECT_NE(error_of([&] {
              signature::generate_key_pair(dir + "/run.key", dir + "/x.pub");
            }).find("never overwritten"),
            std::string::npos);
}

TEST_F(Signature, ASignedFileVerifiesAndAnAlteredOneIsRefused) {
  EXPECT_EQ(signature::sign_file(file, dir + "/run.key"), file + ".sig");
  EXPECT_EQ(fs::file_size(file + ".sig"), 64u);
  EXPECT_NO_THROW(signature::verify_file(file, dir + "/run.pub"));
  {
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(3);
    f.put('X');
  }
  const std::string error = error_of([&] { signature::verify_file(file, dir + "/run.pub"); });
  EXPECT_NE(error.find(file), std::string::npos) << error;
  EXPECT_NE(error.find("does not match"), std::string::npos) << error;
}

TEST_F(Signature, AnotherKeyNoSignatureOrADamagedOneIsRefused) {
  signature::generate_key_pair(dir + "/other.key", dir + "/other.pub");
  signature::sign_file(file, dir + "/other.key");
  EXPECT_NE(error_of([&] { signature::verify_file(file, dir + "/run.pub"); }).find("another key"),
            std::string::npos);
  fs::remove(file + ".sig");
  EXPECT_NE(error_of([&] { signature::verify_file(file, dir + "/run.pub"); }).find("not signed"),
            std::string::npos);
  std::ofstream(file + ".sig") << "short";
  EXPECT_NE(error_of([&] { signature::verify_file(file, dir + "/run.pub"); }).find("64-byte"),
            std::string::npos);
  std::ofstream(dir + "/bad.pub") << "not a key\n";
  signature::sign_file(file, dir + "/run.key");
  const std::string error = error_of([&] { signature::verify_file(file, dir + "/bad.pub"); });
  EXPECT_NE(error.find("bad.pub"), std::string::npos) << error;
}

TEST_F(Signature, OpenSslsCommandLineVerifiesOurSignatures) {
  if (!fs::exists("/usr/bin/openssl")) GTEST_SKIP() << "no /usr/bin/openssl";
  signature::sign_file(file, dir + "/run.key");
  const std::string cmd = "/usr/bin/openssl pkeyutl -verify -pubin -inkey " + dir +
                          "/run.pub -rawin -in " + file + " -sigfile " + file +
                          ".sig > /dev/null 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0);
}

TEST_F(Signature, TheControllerWithATrustKeyRefusesUnsignedOrAlteredFiles) {
  const std::string config = AUVRL_CONFIG_DIR;
  const std::string mission = dir + "/tour.yaml";
  const std::string policy = dir + "/fast.nn";
  {
    std::ifstream in(config + "/missions/tour.yaml");
    std::ofstream out(mission);
    for (std::string line; std::getline(in, line);) {
      out << (line.rfind("vehicle:", 0) == 0 ? "vehicle: " + config + "/vehicles/nessie7.yaml"
                                             : line)
          << "\n";
    }
  }
  fs::copy_file(config + "/policies/fast.nn", policy);
  agent::ControllerProcessOptions options;
  options.mission_path = mission;
  options.policy_path = policy;
  EXPECT_NO_THROW(agent::load_controller_setup(options));  // no trust key: no check
  options.trust_key = dir + "/run.pub";
  EXPECT_NE(error_of([&] { agent::load_controller_setup(options); }).find(mission + ": not signed"),
            std::string::npos);
  signature::sign_file(mission, dir + "/run.key");
  EXPECT_NE(error_of([&] { agent::load_controller_setup(options); }).find(policy + ": not signed"),
            std::string::npos);
  signature::sign_file(policy, dir + "/run.key");
  EXPECT_NO_THROW(agent::load_controller_setup(options));
  std::ofstream(mission, std::ios::app) << "# altered\n";
  EXPECT_NE(error_of([&] { agent::load_controller_setup(options); }).find("does not match"),
            std::string::npos);
}

}  // namespace
