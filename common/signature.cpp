#include "common/signature.hpp"

#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <sys/stat.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "common/nn/file_io.hpp"
#include "common/openssl_error.hpp"

namespace auvrl::signature {

namespace {

constexpr std::size_t kSignatureBytes = 64;  // Ed25519

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;
using Key = std::unique_ptr<EVP_PKEY, decltype(&EVP_PKEY_free)>;
using DigestContext = std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)>;

File open_file(const std::string& path, const char* mode) {
  File f(std::fopen(path.c_str(), mode));
  if (!f) throw std::runtime_error("cannot open " + path);
  return f;
}

/// An Ed25519 key from a PEM file (private or public).
Key read_key(const std::string& pem, bool is_private) {
  File f = open_file(pem, "r");
  Key key(is_private ? PEM_read_PrivateKey(f.get(), nullptr, nullptr, nullptr)
                     : PEM_read_PUBKEY(f.get(), nullptr, nullptr, nullptr),
          EVP_PKEY_free);
  if (!key) {
    throw std::runtime_error(pem + ": not a PEM " + (is_private ? "private" : "public") + " key" +
                             openssl_error());
  }
  if (EVP_PKEY_get_id(key.get()) != EVP_PKEY_ED25519) {
    throw std::runtime_error(pem + ": not an Ed25519 key");
  }
  return key;
}

DigestContext new_context() {
  DigestContext ctx(EVP_MD_CTX_new(), EVP_MD_CTX_free);
  if (!ctx) throw std::runtime_error("OpenSSL: out of memory" + openssl_error());
  return ctx;
}

}  // namespace

std::string signature_path(const std::string& path) { return path + ".sig"; }

void generate_key_pair(const std::string& private_pem, const std::string& public_pem) {
  if (std::filesystem::exists(private_pem)) {
    throw std::runtime_error(private_pem + " exists: a key is never overwritten");
  }
  std::unique_ptr<EVP_PKEY_CTX, decltype(&EVP_PKEY_CTX_free)> ctx(
      EVP_PKEY_CTX_new_id(EVP_PKEY_ED25519, nullptr), EVP_PKEY_CTX_free);
  EVP_PKEY* raw = nullptr;
  if (!ctx || EVP_PKEY_keygen_init(ctx.get()) != 1 || EVP_PKEY_keygen(ctx.get(), &raw) != 1) {
    throw std::runtime_error("cannot generate an Ed25519 key" + openssl_error());
  }
  Key key(raw, EVP_PKEY_free);
  {
    // Readable by its owner only, from the start.
    const mode_t old_mask = umask(077);
    File f(std::fopen(private_pem.c_str(), "wx"));
    umask(old_mask);
    if (!f ||
        PEM_write_PrivateKey(f.get(), key.get(), nullptr, nullptr, 0, nullptr, nullptr) != 1) {
      throw std::runtime_error("cannot write " + private_pem + openssl_error());
    }
  }
  File f = open_file(public_pem, "w");
  if (PEM_write_PUBKEY(f.get(), key.get()) != 1) {
    throw std::runtime_error("cannot write " + public_pem + openssl_error());
  }
}

std::string sign_file(const std::string& path, const std::string& private_pem) {
  const std::vector<std::uint8_t> bytes = nn::read_file(path);
  const Key key = read_key(private_pem, true);
  DigestContext ctx = new_context();
  std::vector<std::uint8_t> sig(kSignatureBytes);
  std::size_t sig_len = sig.size();
  // Ed25519 signs the message itself (no separate digest).
  if (EVP_DigestSignInit(ctx.get(), nullptr, nullptr, nullptr, key.get()) != 1 ||
      EVP_DigestSign(ctx.get(), sig.data(), &sig_len, bytes.data(), bytes.size()) != 1 ||
      sig_len != kSignatureBytes) {
    throw std::runtime_error("cannot sign " + path + " with " + private_pem + openssl_error());
  }
  const std::string out = signature_path(path);
  nn::write_file_atomically(out, sig);
  return out;
}

void verify_file(const std::string& path, const std::string& public_pem) {
  const std::string sig_path = signature_path(path);
  if (!std::filesystem::exists(sig_path)) {
    throw std::runtime_error(path + ": not signed (no " + sig_path + ")");
  }
  const std::vector<std::uint8_t> sig = nn::read_file(sig_path);
  if (sig.size() != kSignatureBytes) {
    throw std::runtime_error(sig_path + ": " + std::to_string(sig.size()) +
                             " bytes, expected a 64-byte Ed25519 signature");
  }
  const std::vector<std::uint8_t> bytes = nn::read_file(path);
  const Key key = read_key(public_pem, false);
  DigestContext ctx = new_context();
  if (EVP_DigestVerifyInit(ctx.get(), nullptr, nullptr, nullptr, key.get()) != 1) {
    throw std::runtime_error("cannot verify with " + public_pem + openssl_error());
  }
  if (EVP_DigestVerify(ctx.get(), sig.data(), sig.size(), bytes.data(), bytes.size()) != 1) {
    ERR_clear_error();
    throw std::runtime_error(path + ": its signature " + sig_path +
                             " does not match (the file was altered, or signed by another key "
                             "than " +
                             public_pem + ")");
  }
}

}  // namespace auvrl::signature
