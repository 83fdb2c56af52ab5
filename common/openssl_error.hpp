// The newest error of OpenSSL's thread-local queue as text, for messages that say why a
// certificate, key, signature or document was refused (common/signature.cpp,
// common/dds_security.cpp).
#pragma once

#include <openssl/err.h>

#include <string>

namespace auvrl {

/// The newest OpenSSL error as prefix + its text ("" if none); the queue is cleared.
inline std::string openssl_error(const char* prefix = ": ") {
  const unsigned long code = ERR_get_error();
  ERR_clear_error();
  if (code == 0) return "";
  char text[256];
  ERR_error_string_n(code, text, sizeof text);
  return prefix + std::string(text);
}

}  // namespace auvrl
