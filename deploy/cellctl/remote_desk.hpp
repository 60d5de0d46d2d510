#pragma once
// The order desk for remote clients, run by `cellctl up` (docs/order-desk.md): per client of
// the deployment file's `clients:`, it takes a product's files in chunks and then the order
// (idl/desk.idl), checks them (names, sizes, digests, the AutomationML description: the same
// errors as `cellctl submit`, sent back), keeps them in the cell's state folder and hands the
// order to the local desk (OrderDesk), which starts its twin. It relays the order's progress
// and, at its end, sends the results (plan.json, animation.gltf) back. Past a limit of the
// deployment file's `desk:` it refuses with the reason and goes on.
//
// DDS threads only queue what comes in; tend(), on cellctl up's loop, does the work: one
// client's upload never stalls another client's reader.

#include <chrono>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "deploy/cellctl/cell_config.hpp"
#include "deploy/cellctl/cell_observer.hpp"
#include "deploy/cellctl/file_transfer.hpp"
#include "services/state/cell_store.hpp"

namespace cellctl {

class RemoteDesk {
 public:
  RemoteDesk(const CellConfig& cell, state::CellStore& store, CellObserver& observer,
             std::function<void(const std::string&)> log);
  ~RemoteDesk();

  void tend();

 private:
  struct Client;
  struct Accepted {  // an order of a client, until its results are sent
    std::string client, submission, request, order;
    std::string last_state;
  };
  struct Answered {  // a final reply, kept for a late reader a while, then unregistered
    Client* client;
    cell::DeskReply reply;
    std::chrono::steady_clock::time_point at;
  };

  void take_order(Client& client, const cell::OrderRequest& request);
  void store_order(Client& client, const cell::OrderRequest& request, const FileAssembly& upload, const std::string& sequence);
  void refuse(Client& client, const cell::OrderRequest& request, const std::string& why, int exit_code);
  void reply(Client& client, const std::string& submission, const std::string& request, const std::string& order,
             cell::DeskState state, const std::string& message, double progress = 0, unsigned result_files = 0,
             int exit_code = 0);
  // Relays its place in the cell's queue, then its progress.
  void follow(Accepted& order, const std::map<std::string, cell::OrderStatus>& statuses, const std::vector<std::string>& queue);
  void finish(Accepted& order, const state::OrderRecord& record);  // the last reply and the results

  const CellConfig& cell_;
  state::CellStore& store_;
  CellObserver& observer_;
  std::function<void(const std::string&)> log_;
  std::map<std::string, std::unique_ptr<Client>> clients_;
  std::vector<Accepted> accepted_;
  std::deque<Answered> answered_;
};

}  // namespace cellctl
