// Signed files a vehicle can trust: Ed25519 signatures (OpenSSL) of policy and mission files.
// A file F is signed by F.sig beside it: the 64 raw bytes of the Ed25519 signature of F's
// bytes, as `openssl pkeyutl -sign -rawin` writes them, so either tool can sign or verify.
// Keys are PEM files (PKCS#8 private key, SubjectPublicKeyInfo public key).
#pragma once

#include <string>

namespace auvrl::signature {

/// The signature file of `path`: path + ".sig".
std::string signature_path(const std::string& path);

/// Writes a new Ed25519 key pair: the private key to private_pem (mode 0600, refused if it
/// exists) and the public key to public_pem. Throws std::runtime_error naming the file.
void generate_key_pair(const std::string& private_pem, const std::string& public_pem);

/// Signs the bytes of `path` with the private key in private_pem and writes signature_path(path)
/// (atomically). Returns that path. Throws std::runtime_error naming the file that is wrong.
std::string sign_file(const std::string& path, const std::string& private_pem);

/// Checks `path` against signature_path(path) with the public key in public_pem. Throws
/// std::runtime_error naming the file and what is wrong: no signature beside it, a signature of
/// the wrong size, or one that does not match (the file was altered, or signed by another key).
void verify_file(const std::string& path, const std::string& public_pem);

}  // namespace auvrl::signature
