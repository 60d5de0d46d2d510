#pragma once
// The cell's public-key infrastructure for DDS-Security, made with the OpenSSL library: a CA
// (ECDSA P-256), one certificate and key per identity, and documents signed by the CA in the
// S/MIME form DDS-Security reads (the same as `openssl smime -sign -text`). File layout:
// services/dds/security.hpp; what each identity may do: deploy/cellctl/pki_policy.hpp.

#include <chrono>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace cellctl::pki {

class PkiError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// From `not_before` to `not_before + days`.
struct Validity {
  std::chrono::system_clock::time_point not_before = std::chrono::system_clock::now() - std::chrono::minutes(5);
  int days = 365;
};

// Writes DIR/ca.key.pem (0600) and DIR/ca.cert.pem; refuses when DIR/ca.key.pem exists.
void make_ca(const std::filesystem::path& dir, const std::string& name, const Validity& validity);

// Writes DIR/identities/NAME/key.pem (0600) and cert.pem (subject CN=NAME, signed by the CA
// in DIR), replacing what was there. `alt_names`: a TLS server's subjectAltName entries
// ("IP:127.0.0.1", "DNS:localhost"), the names a client reaches it by.
void issue_certificate(const std::filesystem::path& dir, const std::string& name, const Validity& validity,
                       const std::vector<std::string>& alt_names = {});

// Writes `document` to `file` (an XML file beside it keeps the text) signed by DIR's CA.
void write_signed(const std::filesystem::path& dir, const std::string& document, const std::filesystem::path& file);

// "2026-11-30T23:00:00", UTC, as DDS-Security's permissions documents write times.
std::string xml_time(std::chrono::system_clock::time_point t);

}  // namespace cellctl::pki
