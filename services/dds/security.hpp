#pragma once
// DDS-Security for a cell participant: authentication (builtin.PKI-DH), access control
// (builtin.Access-Permissions: a governance and a permissions document signed by the cell's
// CA) and encryption (builtin.AES-GCM-GMAC). The files are the ones `cellctl pki init`
// writes (docs/security.md):
//
//   DIR/ca.cert.pem                     the cell's CA: identity CA and permissions CA
//   DIR/governance.p7s                  what the domain protects, signed by the CA
//   DIR/identities/NAME/cert.pem        NAME's certificate (subject CN=NAME), by the CA
//   DIR/identities/NAME/key.pem         NAME's private key (mode 0600)
//   DIR/identities/NAME/permissions.p7s what NAME may publish and read, signed by the CA
//
// The CA's own key (DIR/ca.key.pem) is read by `cellctl pki` only, never by a process.

#include <filesystem>
#include <stdexcept>
#include <string>

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>

#include "services/dds/participant_settings.hpp"

namespace dds {

struct IdentityFiles {
  std::filesystem::path ca_cert, governance, cert, key, permissions;
};

IdentityFiles identity_files(const std::filesystem::path& dir, const std::string& identity);

// "security: what is wrong, and with which file".
class SecurityError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Checks what Fast DDS would refuse with a log line of its own that names no file: a missing
// or unreadable file, a certificate that has expired or is not yet valid, one the CA did not
// sign, a key that is not the certificate's. Throws SecurityError.
void check_identity(const IdentityFiles& files, const std::string& identity);

// Adds the plugin properties to `qos` (after check_identity).
void apply_security(eprosima::fastdds::dds::DomainParticipantQos& qos, const IdentityFiles& files);

}  // namespace dds
