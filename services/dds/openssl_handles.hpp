#pragma once
// OpenSSL objects owned by unique_ptr, and a memory BIO's text: shared by the identity checks
// (security.cpp) and cellctl's PKI (deploy/cellctl/pki.cpp).

#include <memory>
#include <string>

#include <openssl/bio.h>
#include <openssl/x509.h>

namespace openssl {

template <typename T, void (*Free)(T*)>
struct Deleter {
  void operator()(T* p) const { Free(p); }
};
using X509Ptr = std::unique_ptr<X509, Deleter<X509, X509_free>>;
using KeyPtr = std::unique_ptr<EVP_PKEY, Deleter<EVP_PKEY, EVP_PKEY_free>>;
using BioPtr = std::unique_ptr<BIO, Deleter<BIO, BIO_free_all>>;

// What was written to a memory BIO.
inline std::string text_of(BIO* bio) {
  char* data = nullptr;
  const long n = BIO_get_mem_data(bio, &data);
  return std::string(data, static_cast<std::size_t>(n));
}

}  // namespace openssl
