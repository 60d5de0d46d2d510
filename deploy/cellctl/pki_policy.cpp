#include "deploy/cellctl/pki_policy.hpp"

#include <algorithm>
#include <sstream>

#include "deploy/cellctl/file_transfer.hpp"
#include "services/dds/endpoints.hpp"

namespace cellctl::pki {

namespace {

using Topics = std::vector<std::string>;

std::string commands(const std::string& id) { return "cell/commands/" + id; }

Topics operator+(Topics a, const Topics& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// Every process makes 32 readers on this topic at start (services/dds/participant.cpp).
const Topics kEveryone = {"cell/reader_slots"};

// What every resource does (services/node/resource_node.cpp): its capability and command
// events, bids and award replies; it reads calls, awards, releases, cancels, the orders'
// status, the clock and the cell's roster (whether the operator took it out of service).
Grant resource(const std::string& id, const std::string& role, const Topics& own_command_topics, bool moves) {
  Grant g{id, role, {id},
          {"cell/capabilities", "cell/command_events", "cell/negotiation/proposals", "cell/negotiation/replies"},
          own_command_topics + Topics{"cell/cancel_requests", "cell/negotiation/calls", "cell/negotiation/awards",
                                      "cell/negotiation/releases", "cell/orders/status", "cell/orders/twins",
                                      "cell/clock", "cell/roster"} + kEveryone};
  if (moves) {  // it asks cell-sim to move its bodies
    g.publish.push_back("cell/sim/requests");
    g.subscribe.push_back("cell/sim/replies");
  }
  return g;
}

void criteria_xml(std::ostream& out, const char* tag, const Topics& topics, const Topics& partitions) {
  if (topics.empty()) return;
  out << "        <" << tag << ">\n          <topics>\n";
  for (const auto& t : topics) out << "            <topic>" << t << "</topic>\n";
  out << "          </topics>\n";
  if (!partitions.empty()) {
    out << "          <partitions>\n";
    for (const auto& p : partitions) out << "            <partition>" << p << "</partition>\n";
    out << "          </partitions>\n";
  }
  out << "        </" << tag << ">\n";
}

// The owned topics (dds::owned_topic), an order's (dds::order_scoped_topic) and those it speaks
// on as itself in the identity's own partitions when it writes them, in every partition when
// it reads them; the others in the default partition.
void topics_xml(std::ostream& out, const char* tag, const Topics& topics, const Topics& owned_partitions,
                const Topics& as_itself) {
  Topics owned, other;
  for (const auto& t : topics) {
    const bool own = dds::owned_topic(t) || dds::order_scoped_topic(t) ||
                     std::find(as_itself.begin(), as_itself.end(), t) != as_itself.end();
    (own ? owned : other).push_back(t);
  }
  criteria_xml(out, tag, other, {});
  criteria_xml(out, tag, owned, owned_partitions);
}

}  // namespace

std::vector<Grant> cell_grants(const CellConfig& cell) {
  std::vector<Grant> grants;
  grants.push_back({"cell-sim", "cell-sim", {"cell-sim"}, {"cell/sim/replies", "cell/clock", "cell/capabilities"},
                    Topics{"cell/sim/requests", "cell/negotiation/replies", "cell/orders/status", "cell/orders/twins"} +
                        kEveryone});
  Topics commanded;  // what a twin commands: the arms and the robots
  for (const auto& s : cell.stations) {
    grants.push_back(resource(s.id, "station", {commands(s.id), commands(s.arm)}, true));
    grants.back().own_partitions.push_back(s.arm);  // the arm is a resource of the station's process
    commanded.push_back(commands(s.arm));
  }
  Topics buffers;
  for (const auto& b : cell.buffers) {
    grants.push_back(resource(b.id, "buffer", {commands(b.id)}, false));
    grants.back().as_itself = {commands(b.id)};
    buffers.push_back(commands(b.id));
  }
  for (const auto& r : cell.robots) {
    Grant g = resource(r.id, "mobile-robot", {commands(r.id)}, true);
    g.publish = g.publish + buffers;  // the robot has buffers give it parts
    g.as_itself = buffers;
    g.subscribe = g.subscribe + Topics{"cell/capabilities", "cell/command_events"};
    grants.push_back(g);
    commanded.push_back(commands(r.id));
  }
  // One identity per twin that runs at once; each speaks for the orders bound to it alone.
  for (const auto& twin : cell.twin_identity_names()) {
    grants.push_back({twin, "twin", {twin},
                      Topics{"cell/orders/status", "cell/orders/result", "cell/negotiation/calls", "cell/negotiation/awards",
                             "cell/negotiation/releases", "cell/cancel_requests", "cell/sim/requests"} + commanded,
                      Topics{"cell/clock", "cell/capabilities", "cell/negotiation/proposals", "cell/negotiation/replies",
                             "cell/command_events", "cell/sim/replies", "cell/roster"} + kEveryone});
  }
  const Topics observer = Topics{"cell/clock", "cell/capabilities", "cell/orders/status", "cell/orders/result",
                                 "cell/orders/twins", "cell/command_events"} + kEveryone;
  // Both start twins (cellctl run; cellctl up's desk) and bind them to their orders.
  grants.push_back({"cellctl", "cellctl", {}, {"cell/orders/twins", "cell/roster"}, observer});
  // cellctl up: it observes the cell, runs the order desk of every client, and its dashboard
  // follows cell-sim's requests and replies (the robots' moves, the parts placed).
  Grant desk{"order-desk", "order-desk", {}, {"cell/orders/twins", "cell/roster"},
             observer + Topics{"cell/sim/requests", "cell/sim/replies"}};
  for (const auto& c : cell.clients) {
    desk.publish = desk.publish + Topics{desk_topic("replies", c), desk_topic("results", c)};
    desk.subscribe = desk.subscribe + Topics{desk_topic("files", c), desk_topic("orders", c)};
    // A client sends its orders and reads its own answers: nothing of the cell, nor of others.
    grants.push_back({c, "client", {}, {desk_topic("files", c), desk_topic("orders", c)},
                      Topics{desk_topic("replies", c), desk_topic("results", c)} + kEveryone});
  }
  grants.push_back(desk);
  // The dashboard's TLS server and the people who may use it by certificate: no DDS.
  Grant dashboard{"dashboard", "dashboard", {}, {}, {}};
  dashboard.tls_names = {"IP:127.0.0.1", "DNS:localhost"};
  if (!cell.dashboard.empty()) {
    const std::string host = parse_dashboard_address(cell.dashboard).host;
    const bool ip = host.find_first_not_of("0123456789.") == std::string::npos;
    if (host != "127.0.0.1" && host != "0.0.0.0") dashboard.tls_names.push_back((ip ? "IP:" : "DNS:") + host);
  }
  grants.push_back(dashboard);
  for (const auto& o : cell.operators) grants.push_back({o, "operator", {}, {}, {}});
  // The discovery servers relay who is there; they read and write no topic.
  grants.push_back({"discovery", "discovery", {}, {}, kEveryone});
  return grants;
}

std::string governance_xml(int domain) {
  std::ostringstream out;
  out << R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains>
        <id>)" << domain << R"(</id>
      </domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>NONE</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
)";
  return out.str();
}

std::string permissions_xml(const Grant& grant, int domain, const Validity& validity) {
  std::ostringstream out;
  out << R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name=")" << grant.identity << R"(">
      <subject_name>CN=)" << grant.identity << R"(</subject_name>
      <validity>
        <not_before>)" << xml_time(validity.not_before) << R"(</not_before>
        <not_after>)" << xml_time(validity.not_before + std::chrono::hours(24) * validity.days) << R"(</not_after>
      </validity>
      <allow_rule>
        <domains>
          <id>)" << domain << R"(</id>
        </domains>
)";
  topics_xml(out, "publish", grant.publish, grant.own_partitions, grant.as_itself);
  topics_xml(out, "subscribe", grant.subscribe, {"*"}, grant.as_itself);
  out << R"(      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
)";
  return out.str();
}

}  // namespace cellctl::pki
