#include "deploy/cellctl/pki_command.hpp"

#include <iostream>
#include <memory>

#include "deploy/cellctl/cell_config.hpp"
#include "deploy/cellctl/pki.hpp"
#include "deploy/cellctl/pki_policy.hpp"
#include "services/dds/security.hpp"

namespace cellctl {

namespace {

namespace fs = std::filesystem;

struct PkiOptions {
  std::string dir, name, cell = CELL_DEFAULT_FILE;
  int domain = -1;  // -1: the file's
  int days = 365, backdate_days = 0;

  CellConfig load() const {
    CellConfig c = read_cell_config(cell);
    if (domain >= 0) c.domain = domain;
    return c;
  }
  pki::Validity validity() const {
    pki::Validity v;
    v.not_before -= std::chrono::hours(24) * backdate_days;
    v.days = days;
    return v;
  }
};

void add_options(CLI::App* cmd, PkiOptions& o) {
  cmd->add_option("DIR", o.dir, "The cell's security folder (the deployment file's `security:`)")->required();
  cmd->add_option("--cell", o.cell, "Deployment file: its domain and resources")->check(CLI::ExistingFile);
  cmd->add_option("--domain", o.domain, "DDS domain id, instead of the file's")->check(CLI::Range(0, 232));
  cmd->add_option("--days", o.days, "How long certificates and permissions are valid, days")->check(CLI::Range(1, 36500));
}

// The identity's certificate and key, and its permissions signed by the CA.
void issue(const fs::path& dir, const pki::Grant& grant, int domain, const pki::Validity& validity) {
  pki::issue_certificate(dir, grant.identity, validity, grant.tls_names);
  pki::write_signed(dir, pki::permissions_xml(grant, domain, validity), dds::identity_files(dir, grant.identity).permissions);
}

}  // namespace

void add_pki_command(CLI::App& app, int& exit_code) {
  CLI::App* pki_cmd = app.add_subcommand("pki", "The cell's DDS-Security keys, certificates and permissions");
  pki_cmd->require_subcommand(1);
  auto o = std::make_shared<PkiOptions>();

  CLI::App* init = pki_cmd->add_subcommand(
      "init", "Make a CA for the cell, the domain's governance, and an identity for each process, twins and cellctl");
  add_options(init, *o);
  init->callback([o, &exit_code] {
    const CellConfig cell = o->load();
    const fs::path dir = fs::absolute(o->dir);
    const pki::Validity validity = o->validity();
    pki::make_ca(dir, "agile-cell CA, domain " + std::to_string(cell.domain), validity);
    pki::write_signed(dir, pki::governance_xml(cell.domain), dir / "governance.p7s");
    for (const auto& grant : pki::cell_grants(cell)) {
      issue(dir, grant, cell.domain, validity);
      std::cout << "identity " << grant.identity << " (" << grant.role << "): " << (dir / "identities" / grant.identity).string()
                << '\n';
    }
    std::cout << "CA: " << (dir / "ca.cert.pem").string() << "; its key " << (dir / "ca.key.pem").string()
              << " (mode 0600) signs new identities: keep it off the cell's hosts once they are issued\n";
    exit_code = 0;
  });

  CLI::App* issue_cmd = pki_cmd->add_subcommand(
      "issue", "Issue (again) one identity of the cell with the CA in DIR: a new key, certificate and permissions");
  add_options(issue_cmd, *o);
  issue_cmd->add_option("NAME", o->name, "The identity: cell-sim, a resource id of the file, twin-N, cellctl, order-desk, a client, dashboard or an operator")->required();
  issue_cmd->add_option("--backdate-days", o->backdate_days, "Valid from this many days ago (a test: an expired identity)")
      ->check(CLI::NonNegativeNumber);
  issue_cmd->callback([o, &exit_code] {
    const CellConfig cell = o->load();
    std::string known;
    for (const auto& grant : pki::cell_grants(cell)) {
      if (grant.identity != o->name) {
        known += (known.empty() ? "" : ", ") + grant.identity;
        continue;
      }
      issue(fs::absolute(o->dir), grant, cell.domain, o->validity());
      std::cout << "identity " << grant.identity << " (" << grant.role << ") issued\n";
      exit_code = 0;
      return;
    }
    std::cerr << "error: " << o->name << " is no identity of the cell " << cell.file.string() << " (it has " << known << ")\n";
    exit_code = 2;
  });

  // What an OEM (or another host) gets: the CA's certificate, the governance and one identity,
  // never the CA's key nor other identities.
  auto out = std::make_shared<std::string>();
  CLI::App* export_cmd = pki_cmd->add_subcommand(
      "export", "Copy what one identity needs (the CA's certificate, the governance, its folder) to OUT, for another host");
  export_cmd->add_option("DIR", o->dir, "The cell's security folder")->required()->check(CLI::ExistingDirectory);
  export_cmd->add_option("NAME", o->name, "The identity, e.g. a client of `clients:`")->required();
  export_cmd->add_option("OUT", *out, "A new folder, to be passed as --security on the other host")->required();
  export_cmd->callback([o, out, &exit_code] {
    const fs::path dir = o->dir, to = *out;
    const dds::IdentityFiles from = dds::identity_files(dir, o->name);
    if (!fs::exists(from.cert)) {
      std::cerr << "error: " << from.cert.string() << " does not exist: `cellctl pki issue` makes the identity first\n";
      exit_code = 2;
      return;
    }
    if (fs::exists(to)) {
      std::cerr << "error: " << to.string() << " exists: export into a new folder\n";
      exit_code = 2;
      return;
    }
    const dds::IdentityFiles copy = dds::identity_files(to, o->name);
    fs::create_directories(copy.cert.parent_path());
    for (const fs::path& d : {to, to / "identities", copy.cert.parent_path()}) fs::permissions(d, fs::perms::owner_all);
    fs::copy_file(from.ca_cert, copy.ca_cert);
    fs::copy_file(from.governance, copy.governance);
    fs::copy(from.cert.parent_path(), copy.cert.parent_path(), fs::copy_options::recursive | fs::copy_options::overwrite_existing);
    fs::permissions(copy.key, fs::perms::owner_read | fs::perms::owner_write);
    std::cout << "identity " << o->name << " exported to " << to.string() << " (its key " << copy.key.string()
              << ", mode 0600): pass it as --security there\n";
    exit_code = 0;
  });
}

}  // namespace cellctl
