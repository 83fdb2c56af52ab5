#include "launcher/run_signing.hpp"

#include <filesystem>

#include "common/signature.hpp"

namespace auvrl::launcher {

namespace fs = std::filesystem;

std::string ensure_run_key(const std::string& run_dir) {
  const fs::path keys = fs::path(run_dir) / "keys";
  const std::string key = (keys / "run.key").string();
  if (!fs::exists(key)) {
    fs::create_directories(keys);
    signature::generate_key_pair(key, (keys / "run.pub").string());
  }
  return key;
}

std::vector<std::string> sign_policies(const std::string& dir, const std::string& key_path,
                                       std::ostream& out) {
  std::vector<std::string> signed_files;
  try {
    for (const char* name :
         {"policy.nn", "policy_best.nn", "policy_average.nn", "policy_finetuned.nn"}) {
      const std::string path = (fs::path(dir) / name).string();
      if (!fs::exists(path)) continue;
      signature::sign_file(path, key_path);
      signed_files.push_back(path);
    }
  } catch (const std::exception& e) {
    out << "auvrl: cannot sign the policies: " << e.what() << "\n";
    return signed_files;
  }
  if (!signed_files.empty()) {
    out << "auvrl: " << signed_files.size() << (signed_files.size() == 1 ? " policy" : " policies")
        << " signed with " << key_path
        << " (FILE.sig; a vehicle checks them with auv_controller --trust-key "
        << (fs::path(key_path).parent_path() / "run.pub").string() << ")\n";
  }
  return signed_files;
}

}  // namespace auvrl::launcher
