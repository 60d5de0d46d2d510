#include "services/dds/security.hpp"

#include <cstdio>
#include <memory>

#include <openssl/bio.h>
#include <openssl/pem.h>
#include <openssl/x509.h>

#include "services/dds/openssl_handles.hpp"

namespace dds {

namespace {

namespace fs = std::filesystem;

using openssl::BioPtr;
using openssl::KeyPtr;
using openssl::X509Ptr;

std::string where(const std::string& identity, const fs::path& file) {
  return "security: identity '" + identity + "' (" + file.string() + ")";
}

BioPtr open_file(const std::string& identity, const fs::path& file) {
  if (!fs::exists(file)) throw SecurityError(where(identity, file) + ": no such file; `cellctl pki init` writes it");
  BioPtr bio(BIO_new_file(file.c_str(), "r"));
  if (!bio) throw SecurityError(where(identity, file) + ": cannot read the file");
  return bio;
}

X509Ptr read_cert(const std::string& identity, const fs::path& file) {
  BioPtr bio = open_file(identity, file);
  X509Ptr cert(PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr));
  if (!cert) throw SecurityError(where(identity, file) + ": not a PEM certificate");
  return cert;
}

std::string time_text(const ASN1_TIME* t) {
  BioPtr bio(BIO_new(BIO_s_mem()));
  ASN1_TIME_print(bio.get(), t);
  return openssl::text_of(bio.get());
}

// Fast DDS 2.9 takes "file://" followed by the path.
std::string file_uri(const fs::path& p) { return "file://" + fs::absolute(p).string(); }

}  // namespace

IdentityFiles identity_files(const fs::path& dir, const std::string& identity) {
  const fs::path own = dir / "identities" / identity;
  return {dir / "ca.cert.pem", dir / "governance.p7s", own / "cert.pem", own / "key.pem", own / "permissions.p7s"};
}

void check_identity(const IdentityFiles& files, const std::string& identity) {
  const X509Ptr ca = read_cert(identity, files.ca_cert);
  const X509Ptr cert = read_cert(identity, files.cert);
  open_file(identity, files.governance);
  open_file(identity, files.permissions);
  KeyPtr key;
  {
    BioPtr bio = open_file(identity, files.key);
    key.reset(PEM_read_bio_PrivateKey(bio.get(), nullptr, nullptr, nullptr));
    if (!key) throw SecurityError(where(identity, files.key) + ": not a PEM private key");
  }
  if (X509_cmp_current_time(X509_get0_notAfter(cert.get())) <= 0) {
    throw SecurityError(where(identity, files.cert) + ": the certificate expired on " + time_text(X509_get0_notAfter(cert.get())));
  }
  if (X509_cmp_current_time(X509_get0_notBefore(cert.get())) > 0) {
    throw SecurityError(where(identity, files.cert) + ": the certificate is not valid before " +
                        time_text(X509_get0_notBefore(cert.get())));
  }
  if (X509_verify(cert.get(), X509_get0_pubkey(ca.get())) != 1) {
    throw SecurityError(where(identity, files.cert) + ": the certificate is not signed by the cell's CA " +
                        files.ca_cert.string());
  }
  if (X509_check_private_key(cert.get(), key.get()) != 1) {
    throw SecurityError(where(identity, files.key) + ": the key is not the certificate's");
  }
}

void apply_security(eprosima::fastdds::dds::DomainParticipantQos& qos, const IdentityFiles& files) {
  auto& p = qos.properties().properties();
  const std::string auth = "dds.sec.auth.builtin.PKI-DH.", access = "dds.sec.access.builtin.Access-Permissions.";
  p.emplace_back("dds.sec.auth.plugin", "builtin.PKI-DH");
  p.emplace_back(auth + "identity_ca", file_uri(files.ca_cert));
  p.emplace_back(auth + "identity_certificate", file_uri(files.cert));
  p.emplace_back(auth + "private_key", file_uri(files.key));
  p.emplace_back("dds.sec.access.plugin", "builtin.Access-Permissions");
  p.emplace_back(access + "permissions_ca", file_uri(files.ca_cert));
  p.emplace_back(access + "governance", file_uri(files.governance));
  p.emplace_back(access + "permissions", file_uri(files.permissions));
  p.emplace_back("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
}

}  // namespace dds
