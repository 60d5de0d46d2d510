#pragma once
// The DDS domain of every test that starts cell processes or DDS participants: one each. Under
// `ctest -j` tests run at once, and two on one domain hear each other (a cell-sim of a hostile-
// input test once answered the arm of the quotes' run: "no body arm-2/palm"). A new test takes a
// number that is free here, and lists it in kAll, whose static_assert refuses one taken twice.
// Fast DDS takes domains 0 to 232; 42-46 are the deployment files' (deploy/cells), 178 is kept
// for runs by hand, 210 for the benchmarks' (docs/performance.md).

#include <string>

namespace test::domains {

inline constexpr int kDdsEndSaidOnce = 168;
inline constexpr int kOperatorTakesAStationOut = 169;
inline constexpr int kDiscoveryServer = 170;
inline constexpr int kDdsEvents = 171;
inline constexpr int kCancel = 172;
inline constexpr int kDashboardTakesOrders = 173;
inline constexpr int kDashboardInBrowser = 174;  // tests/CMakeLists.txt: dashboard_in_browser
inline constexpr int kDashboard = 175;
inline constexpr int kTwinFrozenDesk = 176;
inline constexpr int kRealBoxOffCentre = 177;
inline constexpr int kRunTwinFrozen = 179;
inline constexpr int kQuotesThrifty = 180;
inline constexpr int kBufferProcess = 181;
inline constexpr int kBufferKilled = 182;
inline constexpr int kBufferRestarts = 183;
inline constexpr int kOrphanedProcess = 184;
inline constexpr int kThreadedTable = 185;
inline constexpr int kLegoTower = 186;
inline constexpr int kCranfield = 187;
inline constexpr int kBadOrderFailsAlone = 188;
inline constexpr int kTwinAlone = 189;
inline constexpr int kTwinBeforeTheCell = 190;
inline constexpr int kResourceDies = 191;
inline constexpr int kTwinDies = 192;
inline constexpr int kTenMixedOrders = 193;
inline constexpr int kTenQueuedOrders = 194;
inline constexpr int kKillsMidOrder = 195;
inline constexpr int kChaos = 196;
inline constexpr int kTwinResumes = 197;
inline constexpr int kDownPauses = 198;
inline constexpr int kDdsRepeatedState = 211;
inline constexpr int kDdsMissedEnd = 47;
inline constexpr int kDdsEndInTheDrain = 48;
inline constexpr int kDdsStateTopics = 199;
inline constexpr int kDdsOutbox = 200;
inline constexpr int kStandbyTwin = 201;
inline constexpr int kSubassemblyResumed = 202;
inline constexpr int kNutOnBolt = 203;
inline constexpr int kUpsideDownTable = 204;
inline constexpr int kQuoteAccuracyA = 205;
inline constexpr int kTwoDiscoveryServers = 206;
inline constexpr int kCancelWhilePlanning = 207;
inline constexpr int kTwoHostsServers = 208;
inline constexpr int kUpPastAHostLimit = 209;
inline constexpr int kBufferStopped = 212;
inline constexpr int kHostileOpening = 213;
inline constexpr int kHostileHugePath = 214;
inline constexpr int kHostileUnhiredFetch = 215;
inline constexpr int kHostileUnawardedGive = 216;
inline constexpr int kHostileIntruderCommand = 217;
inline constexpr int kHostileIntruderSim = 218;
inline constexpr int kHostileBurst = 219;
inline constexpr int kUpRestarts = 220;
inline constexpr int kOneCellPerDomain = 221;
inline constexpr int kQuoteAccuracyB = 222;
inline constexpr int kSecureDashboard = 223;
inline constexpr int kPki = 224;
inline constexpr int kSecureCell = 225;
inline constexpr int kOrderDesk = 226;
inline constexpr int kTwoHosts = 227;
inline constexpr int kQuotesFast = 228;
inline constexpr int kSixtyOrders = 229;
inline constexpr int kUpHung = 230;
inline constexpr int kOrderQueue = 231;
inline constexpr int kQuoteNoAnswer = 232;  // tests/cli/CMakeLists.txt, tests/data/cells/nobody.yaml

inline constexpr int kAll[] = {
    kOperatorTakesAStationOut, kDiscoveryServer, kDdsEvents, kCancel, kDashboardTakesOrders, kDashboardInBrowser,
    kDashboard, kTwinFrozenDesk, kRealBoxOffCentre, kRunTwinFrozen, kQuotesThrifty, kBufferProcess, kBufferKilled,
    kBufferRestarts, kOrphanedProcess, kThreadedTable, kLegoTower, kCranfield, kBadOrderFailsAlone, kTwinAlone,
    kTwinBeforeTheCell, kResourceDies, kTwinDies, kTenMixedOrders, kTenQueuedOrders, kKillsMidOrder, kChaos,
    kTwinResumes, kDownPauses, kDdsStateTopics, kDdsRepeatedState, kDdsMissedEnd, kDdsEndInTheDrain, kDdsEndSaidOnce, kDdsOutbox, kStandbyTwin, kSubassemblyResumed, kNutOnBolt,
    kUpsideDownTable, kQuoteAccuracyA, kTwoDiscoveryServers, kCancelWhilePlanning, kTwoHostsServers, kUpPastAHostLimit,
    kHostileOpening, kHostileHugePath, kHostileUnhiredFetch, kHostileUnawardedGive, kHostileIntruderCommand,
    kHostileIntruderSim, kHostileBurst, kUpRestarts, kOneCellPerDomain, kQuoteAccuracyB, kSecureDashboard, kPki,
    kSecureCell, kOrderDesk, kTwoHosts, kQuotesFast, kSixtyOrders, kUpHung, kOrderQueue, kQuoteNoAnswer,
    kBufferStopped};

constexpr bool all_differ() {
  for (const int a : kAll) {
    int seen = 0;
    for (const int b : kAll) seen += a == b;
    if (seen != 1 || a < 0 || a > 232) return false;
  }
  return true;
}
static_assert(all_differ(), "two tests on one DDS domain (or one past Fast DDS's 232)");

// As a command line takes it.
inline std::string text(int domain) { return std::to_string(domain); }

}  // namespace test::domains
