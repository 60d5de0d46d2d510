#pragma once
// With DDS-Security each running twin has an identity of its own, twin-1 .. twin-N (`cellctl
// pki init` issues N = the deployment file's twin_identities), and whoever starts a twin binds
// its order to that identity on cell/orders/twins (services/dds/twin_bindings.hpp): the cell's
// readers then take an order's status, calls, awards and commands from that twin alone.
// Without security: no identities, no bindings.

#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "deploy/cellctl/processes.hpp"
#include "services/dds/participant.hpp"

namespace cellctl {

struct Twin {
  std::unique_ptr<Process> process;
  std::string identity;  // its DDS-Security identity; "" without security
};

class TwinIdentities {
 public:
  // `participant`: cellctl's own (cellctl up's, run's), which writes the bindings; `names`:
  // CellConfig::twin_identities_in_use(), none without security.
  TwinIdentities(const std::vector<std::string>& names, dds::ParticipantPtr participant);
  ~TwinIdentities();

  // A free identity ("" without security); nullopt while every one is in use.
  std::optional<std::string> take();
  void give_back(const std::string& identity);
  bool any_free() const { return !secure_ || !free_.empty(); }
  // Binds `order` to `identity` for the cell's readers; before the twin writes for it.
  void bind(const std::string& order, const std::string& identity);
  // A twin for `order` started now (`argv`: the twin with its order's options) with a free
  // identity, its order bound to it; no process while every identity runs a twin.
  Twin start(const std::string& order, const std::vector<std::string>& argv, const std::string& stdout_to = "");

 private:
  struct Writer;
  bool secure_;
  std::deque<std::string> free_;  // the longest free first: a name just given back is taken last
  std::map<std::string, std::string> bound_;  // identity -> the order it was last bound to
  std::unique_ptr<Writer> writer_;
};

// The twin's command line with its identity (none without security).
std::vector<std::string> with_identity(std::vector<std::string> argv, const std::string& identity);

}  // namespace cellctl
