#pragma once
// `cellctl submit --remote --client ID PRODUCT.aml`: the OEM's side of the order desk
// (docs/order-desk.md). It sends the product's files and the order over DDS, follows the
// order's progress and writes the results it gets back (plan.json, animation.gltf) to --out.

#include <atomic>
#include <chrono>
#include <string>

#include "services/dds/participant.hpp"

namespace cellctl {

struct RemoteSubmission {
  std::string product, client, submission, out, sequence;
  dds::ParticipantSettings dds;     // the client's identity: dds.security.identity
  std::chrono::seconds wait{30};    // for the desk to answer at all
  bool quote = false;               // a request for a quote (cellctl quote)
  std::string label;                // put before every line it prints ("[cell-a] "): several at once
};

// Its exit code: the order's (0 assembled, 1 failed, 2 a bad description), that of a refusal
// (2 bad input, 1 a limit of the desk), or 3 when no desk answered. `error`: what went wrong.
int submit_remote(const RemoteSubmission& s, const std::atomic<bool>& stop, std::string* error = nullptr);

}  // namespace cellctl
