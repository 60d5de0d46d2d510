#include "deploy/cellctl/pki.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstring>
#include <ctime>
#include <fstream>
#include <memory>

#include <openssl/bn.h>
#include <openssl/ec.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/x509v3.h>

#include "services/dds/openssl_handles.hpp"
#include "services/dds/security.hpp"

namespace cellctl::pki {

namespace {

namespace fs = std::filesystem;

using openssl::BioPtr;
using openssl::KeyPtr;
using openssl::text_of;
using openssl::X509Ptr;
using Pkcs7Ptr = std::unique_ptr<PKCS7, openssl::Deleter<PKCS7, PKCS7_free>>;
using BnPtr = std::unique_ptr<BIGNUM, openssl::Deleter<BIGNUM, BN_free>>;

[[noreturn]] void fail(const std::string& what) {
  const unsigned long code = ERR_get_error();
  char reason[256] = "";
  if (code) ERR_error_string_n(code, reason, sizeof reason);
  throw PkiError("pki: " + what + (code ? std::string(": ") + reason : ""));
}

// Creates or replaces `file` with `mode` (a key: 0600, never readable by others for a moment).
void write_file(const fs::path& file, const std::string& text, mode_t mode) {
  fs::create_directories(file.parent_path());
  const fs::path tmp = file.string() + ".new";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, mode);
  if (fd < 0) throw PkiError("pki: cannot write " + tmp.string() + ": " + std::strerror(errno));
  const bool ok = ::fchmod(fd, mode) == 0 && ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  ::close(fd);
  if (!ok) throw PkiError("pki: cannot write " + tmp.string() + ": " + std::strerror(errno));
  fs::rename(tmp, file);
}

KeyPtr new_key() {
  KeyPtr key(EVP_EC_gen("P-256"));
  if (!key) fail("cannot make an EC P-256 key");
  return key;
}

std::string pem_of_key(EVP_PKEY* key) {
  BioPtr bio(BIO_new(BIO_s_mem()));
  if (!PEM_write_bio_PrivateKey(bio.get(), key, nullptr, nullptr, 0, nullptr, nullptr)) fail("cannot write a key");
  return text_of(bio.get());
}

std::string pem_of_cert(X509* cert) {
  BioPtr bio(BIO_new(BIO_s_mem()));
  if (!PEM_write_bio_X509(bio.get(), cert)) fail("cannot write a certificate");
  return text_of(bio.get());
}

X509Ptr read_cert(const fs::path& file) {
  BioPtr bio(BIO_new_file(file.c_str(), "r"));
  X509Ptr cert(bio ? PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr) : nullptr);
  if (!cert) fail("cannot read the certificate " + file.string());
  return cert;
}

KeyPtr read_key(const fs::path& file) {
  BioPtr bio(BIO_new_file(file.c_str(), "r"));
  KeyPtr key(bio ? PEM_read_bio_PrivateKey(bio.get(), nullptr, nullptr, nullptr) : nullptr);
  if (!key) fail("cannot read the key " + file.string() + " (the CA's key: `cellctl pki init` wrote it)");
  return key;
}

void add_extension(X509* cert, X509* issuer, int nid, const char* value) {
  X509V3_CTX ctx;
  X509V3_set_ctx_nodb(&ctx);
  X509V3_set_ctx(&ctx, issuer, cert, nullptr, nullptr, 0);
  X509_EXTENSION* ext = X509V3_EXT_conf_nid(nullptr, &ctx, nid, value);
  const bool added = ext && X509_add_ext(cert, ext, -1);
  X509_EXTENSION_free(ext);
  if (!added) fail(std::string("cannot add the extension ") + value);
}

// Signed by `issuer_key`; self-signed when `issuer` is null.
X509Ptr make_cert(const std::string& common_name, EVP_PKEY* key, X509* issuer, EVP_PKEY* issuer_key,
                  const Validity& validity, const std::vector<std::string>& alt_names = {}) {
  X509Ptr cert(X509_new());
  BnPtr serial(BN_new());
  if (!cert || !serial || !BN_rand(serial.get(), 63, BN_RAND_TOP_ANY, BN_RAND_BOTTOM_ANY) ||
      !BN_to_ASN1_INTEGER(serial.get(), X509_get_serialNumber(cert.get()))) {
    fail("cannot make a certificate");
  }
  if (!X509_set_version(cert.get(), 2)) fail("cannot make a certificate");
  std::time_t from = std::chrono::system_clock::to_time_t(validity.not_before);
  if (!X509_time_adj_ex(X509_getm_notBefore(cert.get()), 0, 0, &from) ||
      !X509_time_adj_ex(X509_getm_notAfter(cert.get()), validity.days, 0, &from)) {
    fail("cannot set the validity");
  }
  X509_NAME* name = X509_get_subject_name(cert.get());
  if (!X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_UTF8, reinterpret_cast<const unsigned char*>(common_name.c_str()), -1,
                                  -1, 0) ||
      !X509_set_issuer_name(cert.get(), issuer ? X509_get_subject_name(issuer) : name) || !X509_set_pubkey(cert.get(), key)) {
    fail("cannot make the certificate of " + common_name);
  }
  X509* signer = issuer ? issuer : cert.get();
  add_extension(cert.get(), signer, NID_basic_constraints, issuer ? "critical,CA:FALSE" : "critical,CA:TRUE");
  add_extension(cert.get(), signer, NID_key_usage, issuer ? "critical,digitalSignature,keyAgreement" : "critical,keyCertSign,cRLSign,digitalSignature");
  add_extension(cert.get(), signer, NID_subject_key_identifier, "hash");
  if (!alt_names.empty()) {
    std::string names;
    for (const auto& n : alt_names) names += (names.empty() ? "" : ",") + n;
    add_extension(cert.get(), signer, NID_subject_alt_name, names.c_str());
  }
  if (!X509_sign(cert.get(), issuer_key, EVP_sha256())) fail("cannot sign the certificate of " + common_name);
  return cert;
}

}  // namespace

void make_ca(const fs::path& dir, const std::string& name, const Validity& validity) {
  const fs::path key_file = dir / "ca.key.pem";
  for (const fs::path& f : {key_file, dir / "ca.cert.pem"}) {
    if (fs::exists(f)) throw PkiError("pki: " + f.string() + " exists: a cell keeps its CA (`cellctl pki issue` adds identities)");
  }
  fs::create_directories(dir);
  fs::permissions(dir, fs::perms::owner_all);
  KeyPtr key = new_key();
  X509Ptr cert = make_cert(name, key.get(), nullptr, key.get(), validity);
  write_file(key_file, pem_of_key(key.get()), 0600);
  write_file(dir / "ca.cert.pem", pem_of_cert(cert.get()), 0644);
}

void issue_certificate(const fs::path& dir, const std::string& name, const Validity& validity,
                       const std::vector<std::string>& alt_names) {
  const X509Ptr ca = read_cert(dir / "ca.cert.pem");
  const KeyPtr ca_key = read_key(dir / "ca.key.pem");
  const dds::IdentityFiles files = dds::identity_files(dir, name);
  fs::create_directories(files.cert.parent_path());
  fs::permissions(files.cert.parent_path(), fs::perms::owner_all);
  KeyPtr key = new_key();
  X509Ptr cert = make_cert(name, key.get(), ca.get(), ca_key.get(), validity, alt_names);
  write_file(files.key, pem_of_key(key.get()), 0600);
  write_file(files.cert, pem_of_cert(cert.get()), 0644);
}

void write_signed(const fs::path& dir, const std::string& document, const fs::path& file) {
  const X509Ptr ca = read_cert(dir / "ca.cert.pem");
  const KeyPtr ca_key = read_key(dir / "ca.key.pem");
  const int flags = PKCS7_DETACHED | PKCS7_STREAM | PKCS7_TEXT;
  BioPtr in(BIO_new_mem_buf(document.data(), static_cast<int>(document.size())));
  Pkcs7Ptr p7(PKCS7_sign(ca.get(), ca_key.get(), nullptr, in.get(), flags));
  if (!p7) fail("cannot sign " + file.string());
  BioPtr out(BIO_new(BIO_s_mem()));
  BioPtr again(BIO_new_mem_buf(document.data(), static_cast<int>(document.size())));
  if (!SMIME_write_PKCS7(out.get(), p7.get(), again.get(), flags)) fail("cannot write " + file.string());
  write_file(fs::path(file).replace_extension(".xml"), document, 0644);
  write_file(file, text_of(out.get()), 0644);
}

std::string xml_time(std::chrono::system_clock::time_point t) {
  const std::time_t s = std::chrono::system_clock::to_time_t(t);
  std::tm utc{};
  gmtime_r(&s, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &utc);
  return text;
}

}  // namespace cellctl::pki
