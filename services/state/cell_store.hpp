#pragma once
// The cell's durable state, in one SQLite database (`<state_dir>/cell.db`) that every process
// of the cell opens: the stock of each buffer, where every part handed out is, the command a
// resource was executing, which order holds which exclusive resource, the orders' states,
// and a journal of what happened. Why SQLite and not Fast DDS's persistence service:
// docs/durable-state.md.
//
// Every change is one short transaction (BEGIN IMMEDIATE ... COMMIT, in WAL mode with
// synchronous=FULL): a process killed at any moment leaves either all of a change or none
// of it, and a part moves from one place to the next in the same transaction that takes it
// from the last, so that for every part type, at every moment,
//
//   initial stock = in buffers + assembled + on stations + in transit + held for inspection.
//
// A part on its way is named by its order and its body in cell-sim (the command's `part`).
// The store knows no products: part types and places are names.

#include <sqlite3.h>

#include <filesystem>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace state {

// Where a part handed out by a buffer is.
// on_station: at the station's dock, delivered; placed: assembled into the product on the
// station (not finished yet); in_gripper: the arm holds it. All three stand on the station.
enum class Place { in_transit, on_station, in_gripper, placed, assembled, inspection, returned };
const char* place_name(Place p);

struct PartCount {
  int initial = 0, in_buffers = 0, assembled = 0, on_stations = 0, in_transit = 0, inspection = 0;
  int accounted() const { return in_buffers + assembled + on_stations + in_transit + inspection; }
};

struct PartRecord {
  std::string order, part, part_type, buffer;
  std::string holder;   // the robot or arm that holds it; placed: the subassembly built aside it is in
  Place place = Place::in_transit;
  std::string station;  // where it was delivered
};

// What a resource has taken on for an order: the awards (calls) it confirmed; `holds`: the
// order holds the (exclusive) resource, rather than waiting for it or having work queued.
struct BookingRecord {
  std::string order;
  std::vector<std::string> calls;
  double duration = 0;
  bool holds = false;
};

struct CommandRecord {
  std::string resource, command_id, order, operation, part;
};

// An order as the cell's order desk keeps it: what to build (the product file, the output
// folder, the planners), its state as its twin last said, and the twin's exit code once it
// ended (-1 before). `attempts`: the twins started for it.
struct OrderRecord {
  std::string order, state, reason, product, out, sequence, path;
  int exit_code = -1;
  int attempts = 0;
  bool quote = false;  // an order for a quote: virtual assembly only (docs/quotes.md)
  // A remote client's order: the client and its request's id (the desk answers it again
  // after a restart of cellctl up); "" for a local one.
  std::string client{}, request{};
  long arrival = 0;    // the order's place in the cell's arrival order (its row; set by the store)
  // Who asked to cancel it ("dashboard", "cellctl"); "" while nobody did (request_cancel).
  std::string cancelled_by{};
  bool ended() const;  // DONE or FAILED
};

// A step of the plan an order's physical assembly follows: what it puts in (a part's name,
// or a subassembly's for the step inserting it) and the trajectory virtual assembly took.
struct PlanStepRecord {
  std::string step, trajectory;
  bool operator==(const PlanStepRecord& o) const { return step == o.step && trajectory == o.trajectory; }
};

// A resource the operator took out of service.
struct ServiceRecord {
  std::string reason, by;
  double since = 0;  // Unix time, s
};

struct JournalEntry {
  long seq = 0;
  double time = 0;  // Unix time, s
  std::string source, event, order, detail;
};

// A line of the journal, written with the change it tells of (its order is the change's).
struct JournalLine {
  std::string source, event, detail;
};

class StoreError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class CellStore {
 public:
  // Opens (creating the folder, the file and the tables where missing) `dir/cell.db`.
  explicit CellStore(const std::filesystem::path& dir);
  ~CellStore();
  CellStore(const CellStore&) = delete;
  CellStore& operator=(const CellStore&) = delete;

  static std::filesystem::path file_in(const std::filesystem::path& dir) { return dir / "cell.db"; }

  // Inventory. `seed` is the deployment file's stock: a buffer seen the first time starts
  // from it; afterwards the stored counts are the truth. Returns the counts now.
  std::map<std::string, int> open_buffer(const std::string& buffer, const std::map<std::string, int>& seed);
  // One part of `type` leaves `buffer` for `order` (its body `part`), carried by `carrier`.
  // Throws StoreError when the buffer has none.
  void give(const std::string& buffer, const std::string& type, const std::string& order, const std::string& part,
            const std::string& carrier);
  // Whether `buffer` gave the part to `carrier` and it is still on its way: a give repeated
  // after a restart that had done it (its answer was lost with the process).
  bool given(const std::string& buffer, const std::string& order, const std::string& part,
             const std::string& carrier) const;
  // The gives `buffer` counted out whose commands its last process never answered (it ended
  // between the two): the process after it answers them ABORTED, so their parts go back to
  // its stock, and to what it keeps for their orders. Returns those parts, as they were.
  std::vector<PartRecord> undo_unanswered_gives(const std::string& buffer);
  // Parts a buffer keeps for an order that won its award (counted down as they are given,
  // dropped when the order ends): order -> type -> count.
  void keep(const std::string& buffer, const std::string& order, const std::string& type, int count);
  void unkeep(const std::string& buffer, const std::string& order);
  std::map<std::string, std::map<std::string, int>> kept(const std::string& buffer) const;
  // The part reached `station` (a robot put it down at its dock).
  void deliver(const std::string& order, const std::string& part, const std::string& station);
  // Several parts at once: a subassembly, gripped by its base, carried and released whole.
  void grip(const std::string& order, const std::vector<std::string>& parts, const std::string& arm);
  // Let go by the arm. `into` "product": placed in the product on the station; "aside:NAME":
  // placed in the subassembly NAME built beside it; anything else: they stand on the
  // station. The record is the release's own: no twin that dies after it leaves them "at the
  // dock".
  void release(const std::string& order, const std::vector<std::string>& parts, const std::string& into = "");
  void set_aside(const std::string& order, const std::string& part);
  // The order's product is finished: its parts on the station become assembled.
  void assemble(const std::string& order);
  // A carrier (a robot) that restarted gives what it carried back to the buffers it came
  // from; an arm that restarted leaves what it gripped for inspection. Each returns the
  // parts it moved, as they were (the caller journals them).
  std::vector<PartRecord> return_carried(const std::string& carrier);
  std::vector<PartRecord> hold_for_inspection(const std::string& holder);

  std::map<std::string, PartCount> inventory() const;
  std::vector<PartRecord> parts(const std::string& order = "") const;

  // The commands a resource has taken on (queued or under way), so that the process that
  // follows a crash can answer them.
  void command_taken(const CommandRecord& command);
  void command_ended(const std::string& resource, const std::string& command_id);
  // The commands the resource had taken on when its last process ended, taken out.
  std::vector<CommandRecord> take_interrupted(const std::string& resource);
  // The commands of an order some resource has taken on and not ended.
  std::vector<CommandRecord> commands_of(const std::string& order) const;

  // What a resource has taken on, in its order (the holder first), replacing what was.
  void set_bookings(const std::string& resource, const std::vector<BookingRecord>& bookings);
  std::vector<BookingRecord> bookings(const std::string& resource) const;
  // Resource -> the order that holds it.
  std::map<std::string, std::string> holders() const;

  // A new order, SUBMITTED; false when an order of that id exists.
  bool submit_order(const OrderRecord& order);
  void set_order(const std::string& order, const std::string& state, const std::string& reason = "", int exit_code = -1);
  // The order's new state and the journal's line of it in one transaction: whoever reads the
  // state finds the line already there. Two writes let the desk start the next order between
  // a twin's DONE and the journal's "DONE", and the journal then showed one order more under
  // way than max_twins.
  void set_order(const std::string& order, const std::string& state, const std::string& reason, int exit_code,
                 const JournalLine& line);
  // Asks that the order be cancelled (its twin fails it with "cancelled by WHO", through the
  // cleanup any failure takes; an order no twin has started is failed by the cell's desk).
  // False when the cell has no such order or it has ended.
  bool request_cancel(const std::string& order, const std::string& who);
  // Who asked to cancel the order; "" when nobody did.
  std::string cancel_requested(const std::string& order) const;
  // Takes the resource out of service, saying why (it takes no new work; what it took on it
  // finishes), or with `reason` "" back into service. The cell's roster carries it to the
  // resource (cellctl up).
  void set_out_of_service(const std::string& resource, const std::string& reason, const std::string& by);
  // The resources out of service, by id.
  std::map<std::string, ServiceRecord> out_of_service() const;
  // One more twin started for the order; the attempts so far.
  int count_attempt(const std::string& order);
  std::vector<OrderRecord> orders() const;  // in the order they came
  // Stored when physical assembly begins, so that a twin taking the order up follows it.
  void set_plan(const std::string& order, const std::vector<PlanStepRecord>& steps);
  std::vector<PlanStepRecord> plan_of(const std::string& order) const;
  // An order of the cell's desk that has not ended: when its twin dies, the cell starts
  // another, so what the order booked and built waits for it.
  bool awaits_twin(const std::string& order) const;

  void journal(const std::string& source, const std::string& event, const std::string& order = "",
               const std::string& detail = "");
  std::vector<JournalEntry> journal_since(long seq = 0) const;
  int count_events(const std::string& source, const std::string& event) const;

  // "ok", or what PRAGMA integrity_check found.
  std::string integrity() const;

 private:
  class Statement;
  class Transaction;
  void exec(const char* sql) const;
  void add_columns_of_later_versions();
  long schema_version() const;  // PRAGMA user_version
  // The part, on its way, goes back to the buffer it came from (within a transaction).
  void put_back(const PartRecord& part);
  std::vector<PartRecord> parts_held(const std::string& holder, Place place) const;
  // In one transaction: each part that is `from` (or placed into a subassembly aside, with
  // `or_placed_aside`) goes `to`.
  void move_parts(const std::string& order, const std::vector<std::string>& parts, Place to, const std::string& holder,
                  const char* from, bool or_placed_aside = false);
  sqlite3* db_ = nullptr;
};

}  // namespace state
