#include "services/state/cell_store.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

namespace state {
namespace {

// Stored in the database (user_version) once it has kSchema and every later column: one more
// whenever either changes.
constexpr long kSchemaVersion = 1;
constexpr const char* kSchema = R"sql(
CREATE TABLE IF NOT EXISTS stock(
  buffer TEXT NOT NULL, part_type TEXT NOT NULL,
  initial INTEGER NOT NULL, count INTEGER NOT NULL CHECK(count >= 0),
  PRIMARY KEY(buffer, part_type));
CREATE TABLE IF NOT EXISTS kept(
  buffer TEXT NOT NULL, order_id TEXT NOT NULL, part_type TEXT NOT NULL, count INTEGER NOT NULL CHECK(count >= 0),
  PRIMARY KEY(buffer, order_id, part_type));
CREATE TABLE IF NOT EXISTS parts(
  order_id TEXT NOT NULL, part TEXT NOT NULL, part_type TEXT NOT NULL, buffer TEXT NOT NULL,
  place TEXT NOT NULL CHECK(place IN ('in_transit','on_station','in_gripper','placed','assembled','inspection',
                                     'returned')),
  holder TEXT NOT NULL DEFAULT '', station TEXT NOT NULL DEFAULT '',
  from_kept INTEGER NOT NULL DEFAULT 0,
  PRIMARY KEY(order_id, part));
CREATE TABLE IF NOT EXISTS commands(
  resource TEXT NOT NULL, command_id TEXT NOT NULL, order_id TEXT NOT NULL, operation TEXT NOT NULL,
  part TEXT NOT NULL, PRIMARY KEY(resource, command_id));
CREATE TABLE IF NOT EXISTS bookings(
  resource TEXT NOT NULL, position INTEGER NOT NULL, order_id TEXT NOT NULL, holds INTEGER NOT NULL,
  duration REAL NOT NULL, call_id TEXT NOT NULL);
CREATE INDEX IF NOT EXISTS bookings_of ON bookings(resource);
CREATE TABLE IF NOT EXISTS orders(
  order_id TEXT PRIMARY KEY, state TEXT NOT NULL, reason TEXT NOT NULL DEFAULT '', updated REAL,
  product TEXT NOT NULL DEFAULT '', out_dir TEXT NOT NULL DEFAULT '', sequence TEXT NOT NULL DEFAULT '',
  path_planner TEXT NOT NULL DEFAULT '', exit_code INTEGER, attempts INTEGER NOT NULL DEFAULT 0,
  quote INTEGER NOT NULL DEFAULT 0, client TEXT NOT NULL DEFAULT '', request TEXT NOT NULL DEFAULT '',
  cancelled_by TEXT NOT NULL DEFAULT '');
CREATE TABLE IF NOT EXISTS out_of_service(
  resource TEXT PRIMARY KEY, reason TEXT NOT NULL, by TEXT NOT NULL, since REAL NOT NULL);
CREATE TABLE IF NOT EXISTS plan_steps(
  order_id TEXT NOT NULL, position INTEGER NOT NULL, step TEXT NOT NULL, trajectory TEXT NOT NULL,
  PRIMARY KEY(order_id, position));
CREATE TABLE IF NOT EXISTS journal(
  seq INTEGER PRIMARY KEY AUTOINCREMENT, time REAL NOT NULL, source TEXT NOT NULL, event TEXT NOT NULL,
  order_id TEXT NOT NULL, detail TEXT NOT NULL);
)sql";

double unix_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

Place place_of(const std::string& name) {
  for (Place p : {Place::in_transit, Place::on_station, Place::in_gripper, Place::placed, Place::assembled,
                  Place::inspection, Place::returned}) {
    if (name == place_name(p)) return p;
  }
  throw StoreError("unknown place '" + name + "' in the parts table");
}

}  // namespace

const char* place_name(Place p) {
  switch (p) {
    case Place::in_transit: return "in_transit";
    case Place::on_station: return "on_station";
    case Place::in_gripper: return "in_gripper";
    case Place::placed: return "placed";
    case Place::assembled: return "assembled";
    case Place::inspection: return "inspection";
    case Place::returned: return "returned";
  }
  return "?";
}

// A prepared statement, its parameters bound in order.
class CellStore::Statement {
 public:
  Statement(sqlite3* db, const char* sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr) != SQLITE_OK) fail("prepare");
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  template <class... Args>
  Statement& bind(const Args&... args) {
    int i = 0;
    (bind_one(++i, args), ...);
    return *this;
  }
  // True while there is a row.
  bool step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc != SQLITE_DONE) fail("step");
    return false;
  }
  std::string text(int column) const {
    const auto* t = sqlite3_column_text(stmt_, column);
    return t ? reinterpret_cast<const char*>(t) : "";
  }
  long integer(int column) const { return static_cast<long>(sqlite3_column_int64(stmt_, column)); }
  double real(int column) const { return sqlite3_column_double(stmt_, column); }

 private:
  void bind_one(int i, const std::string& s) { sqlite3_bind_text(stmt_, i, s.data(), static_cast<int>(s.size()), SQLITE_TRANSIENT); }
  void bind_one(int i, const char* s) { sqlite3_bind_text(stmt_, i, s, -1, SQLITE_TRANSIENT); }
  void bind_one(int i, long v) { sqlite3_bind_int64(stmt_, i, v); }
  void bind_one(int i, int v) { sqlite3_bind_int64(stmt_, i, v); }
  void bind_one(int i, double v) { sqlite3_bind_double(stmt_, i, v); }
  [[noreturn]] void fail(const char* what) const {
    throw StoreError(std::string("cell state: ") + what + ": " + sqlite3_errmsg(db_));
  }
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

// BEGIN IMMEDIATE (the write lock at once, so that two writers never deadlock upgrading a
// read lock) ... COMMIT; rolled back when left by an exception.
class CellStore::Transaction {
 public:
  explicit Transaction(const CellStore& store, const char* begin = "BEGIN IMMEDIATE") : store_(store) {
    store_.exec(begin);
  }
  ~Transaction() {
    if (!done_) sqlite3_exec(store_.db_, "ROLLBACK", nullptr, nullptr, nullptr);
  }
  void commit() {
    store_.exec("COMMIT");
    done_ = true;
  }

 private:
  const CellStore& store_;
  bool done_ = false;
};

CellStore::CellStore(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw StoreError("cell state: cannot create " + dir.string() + ": " + ec.message());
  const std::string file = file_in(dir).string();
  if (sqlite3_open_v2(file.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX,
                      nullptr) != SQLITE_OK) {
    const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    throw StoreError("cell state: cannot open " + file + ": " + why);
  }
  // Several processes write: a writer waits for another's short transaction rather than fail.
  sqlite3_busy_timeout(db_, 10000);
  // Setting up can still meet "database is locked" at once, without the busy handler (the
  // switch to WAL while the cell's processes open the database together, on a loaded
  // machine: a mobile robot died of it): tried again for up to 10 s.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  for (int attempt = 1;; ++attempt) {
    try {
      exec("PRAGMA journal_mode=WAL");
      exec("PRAGMA synchronous=FULL");
      exec("PRAGMA foreign_keys=ON");
      // A database that has the schema already is only read here: sixty twins opening it at
      // once each took the write lock to create what was there, and some waited past the
      // busy timeout ("database is locked") and failed their orders.
      if (schema_version() == kSchemaVersion) return;
      Transaction t(*this);
      exec(kSchema);
      add_columns_of_later_versions();
      exec(("PRAGMA user_version=" + std::to_string(kSchemaVersion)).c_str());
      t.commit();
      return;
    } catch (const StoreError&) {
      const int code = sqlite3_errcode(db_) & 0xff;
      if ((code == SQLITE_BUSY || code == SQLITE_LOCKED) && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(std::min(20 * attempt, 200)));
        continue;
      }
      sqlite3_close(db_);
      throw;
    } catch (...) {
      sqlite3_close(db_);
      throw;
    }
  }
}

CellStore::~CellStore() { sqlite3_close(db_); }

long CellStore::schema_version() const {
  Statement v(db_, "PRAGMA user_version");
  return v.step() ? v.integer(0) : 0;
}

// A database written before a column existed gets it, with its default.
void CellStore::add_columns_of_later_versions() {
  const auto has = [this](const char* table, const char* column) {
    Statement c(db_, "SELECT 1 FROM pragma_table_info(?) WHERE name = ?");
    c.bind(table, column);
    return c.step();
  };
  if (!has("orders", "quote")) exec("ALTER TABLE orders ADD COLUMN quote INTEGER NOT NULL DEFAULT 0");
  if (!has("orders", "client")) {
    exec("ALTER TABLE orders ADD COLUMN client TEXT NOT NULL DEFAULT ''; "
         "ALTER TABLE orders ADD COLUMN request TEXT NOT NULL DEFAULT ''");
  }
  if (!has("orders", "cancelled_by")) exec("ALTER TABLE orders ADD COLUMN cancelled_by TEXT NOT NULL DEFAULT ''");
  if (!has("parts", "from_kept")) {
    // A give under way when the cell was upgraded is undone as before: kept for its order again.
    exec("ALTER TABLE parts ADD COLUMN from_kept INTEGER NOT NULL DEFAULT 0; "
         "UPDATE parts SET from_kept = 1 WHERE place = 'in_transit'");
  }
}

void CellStore::exec(const char* sql) const {
  char* error = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string why = error ? error : sqlite3_errmsg(db_);
    sqlite3_free(error);
    throw StoreError(std::string("cell state: ") + why);
  }
}

std::map<std::string, int> CellStore::open_buffer(const std::string& buffer, const std::map<std::string, int>& seed) {
  Transaction t(*this);
  Statement known(db_, "SELECT COUNT(*) FROM stock WHERE buffer = ?");
  known.bind(buffer).step();
  if (known.integer(0) == 0) {
    for (const auto& [type, count] : seed) {
      Statement(db_, "INSERT INTO stock(buffer, part_type, initial, count) VALUES(?, ?, ?, ?)")
          .bind(buffer, type, count, count)
          .step();
    }
  }
  std::map<std::string, int> counts;
  Statement rows(db_, "SELECT part_type, count FROM stock WHERE buffer = ?");
  rows.bind(buffer);
  while (rows.step()) counts[rows.text(0)] = static_cast<int>(rows.integer(1));
  t.commit();
  return counts;
}

void CellStore::give(const std::string& buffer, const std::string& type, const std::string& order,
                     const std::string& part, const std::string& carrier) {
  Transaction t(*this);
  Statement take(db_, "UPDATE stock SET count = count - 1 WHERE buffer = ? AND part_type = ? AND count > 0");
  take.bind(buffer, type).step();
  if (sqlite3_changes(db_) != 1) throw StoreError("buffer " + buffer + " has no " + type + " in its stored stock");
  Statement(db_, "UPDATE kept SET count = count - 1 WHERE buffer = ? AND order_id = ? AND part_type = ? AND count > 0")
      .bind(buffer, order, type)
      .step();
  // Whether the part was one the order kept: an undone give keeps it again, or not.
  const int from_kept = sqlite3_changes(db_);
  // A part given back earlier may be handed out again under the same name.
  Statement put(db_,
                "INSERT INTO parts(order_id, part, part_type, buffer, place, holder, from_kept) "
                "VALUES(?, ?, ?, ?, 'in_transit', ?, ?) "
                "ON CONFLICT(order_id, part) DO UPDATE SET part_type = excluded.part_type, buffer = excluded.buffer, "
                "place = 'in_transit', holder = excluded.holder, station = '', from_kept = excluded.from_kept "
                "WHERE place = 'returned'");
  put.bind(order, part, type, buffer, carrier, from_kept).step();
  if (sqlite3_changes(db_) != 1) throw StoreError("part " + part + " of order " + order + " was handed out already");
  t.commit();
}

void CellStore::put_back(const PartRecord& p) {
  Statement(db_, "UPDATE stock SET count = count + 1 WHERE buffer = ? AND part_type = ?").bind(p.buffer, p.part_type).step();
  Statement(db_, "UPDATE parts SET place = 'returned', holder = '' WHERE order_id = ? AND part = ?").bind(p.order, p.part).step();
}

bool CellStore::given(const std::string& buffer, const std::string& order, const std::string& part,
                      const std::string& carrier) const {
  Statement row(db_, "SELECT 1 FROM parts WHERE order_id = ? AND part = ? AND buffer = ? AND holder = ? "
                     "AND place = 'in_transit'");
  row.bind(order, part, buffer, carrier);
  return row.step();
}

std::vector<PartRecord> CellStore::undo_unanswered_gives(const std::string& buffer) {
  Transaction t(*this);
  Statement rows(db_, "SELECT p.order_id, p.part, p.part_type, p.holder, p.from_kept FROM parts p JOIN commands c "
                      "ON c.resource = p.buffer AND c.order_id = p.order_id AND c.part = p.part AND c.operation = 'give' "
                      "WHERE p.buffer = ? AND p.place = 'in_transit' ORDER BY p.order_id, p.part");
  rows.bind(buffer);
  std::vector<PartRecord> undone;
  std::vector<bool> kept;
  while (rows.step()) {
    undone.push_back({rows.text(0), rows.text(1), rows.text(2), buffer, rows.text(3), Place::in_transit, ""});
    kept.push_back(rows.integer(4) != 0);
  }
  for (std::size_t i = 0; i < undone.size(); ++i) {
    put_back(undone[i]);
    if (!kept[i]) continue;  // taken from the free stock: it goes back there
    Statement(db_, "UPDATE kept SET count = count + 1 WHERE buffer = ? AND order_id = ? AND part_type = ?")
        .bind(buffer, undone[i].order, undone[i].part_type)
        .step();
  }
  t.commit();
  return undone;
}

void CellStore::keep(const std::string& buffer, const std::string& order, const std::string& type, int count) {
  Transaction t(*this);
  Statement(db_, "INSERT INTO kept(buffer, order_id, part_type, count) VALUES(?, ?, ?, ?) "
                 "ON CONFLICT(buffer, order_id, part_type) DO UPDATE SET count = count + excluded.count")
      .bind(buffer, order, type, count)
      .step();
  t.commit();
}

void CellStore::unkeep(const std::string& buffer, const std::string& order) {
  Transaction t(*this);
  Statement(db_, "DELETE FROM kept WHERE buffer = ? AND order_id = ?").bind(buffer, order).step();
  t.commit();
}

std::map<std::string, std::map<std::string, int>> CellStore::kept(const std::string& buffer) const {
  Statement rows(db_, "SELECT order_id, part_type, count FROM kept WHERE buffer = ? AND count > 0");
  rows.bind(buffer);
  std::map<std::string, std::map<std::string, int>> out;
  while (rows.step()) out[rows.text(0)][rows.text(1)] = static_cast<int>(rows.integer(2));
  return out;
}

void CellStore::move_parts(const std::string& order, const std::vector<std::string>& parts, Place to,
                           const std::string& holder, const char* from, bool or_placed_aside) {
  Transaction t(*this);
  std::vector<std::string> elsewhere;
  for (const std::string& part : parts) {
    Statement(db_, "UPDATE parts SET place = ?, holder = ? WHERE order_id = ? AND part = ? AND "
                   "(place = ? OR (? AND place = 'placed' AND holder <> ''))")
        .bind(place_name(to), holder, order, part, from, or_placed_aside ? 1 : 0)
        .step();
    if (sqlite3_changes(db_) != 1) elsewhere.push_back(part);
  }
  t.commit();
  // A part that was not where this move starts (handed out before the cell kept state, or
  // moved by a process that was killed before it could say so): the journal tells.
  for (const std::string& part : elsewhere) {
    journal(holder, std::string("unexpected ") + place_name(to), order,
            part + " was not " + from + (or_placed_aside ? " or in a subassembly aside" : ""));
  }
}

void CellStore::deliver(const std::string& order, const std::string& part, const std::string& station) {
  Transaction t(*this);
  Statement(db_, "UPDATE parts SET place = 'on_station', holder = '', station = ? "
                 "WHERE order_id = ? AND part = ? AND place = 'in_transit'")
      .bind(station, order, part)
      .step();
  const bool moved = sqlite3_changes(db_) == 1;
  t.commit();
  if (!moved) journal(station, "unexpected on_station", order, part + " was not in_transit");
}

void CellStore::grip(const std::string& order, const std::vector<std::string>& parts, const std::string& arm) {
  // At the dock, or placed in a subassembly built aside that the arm now carries whole.
  move_parts(order, parts, Place::in_gripper, arm, "on_station", true);
}

void CellStore::release(const std::string& order, const std::vector<std::string>& parts, const std::string& into) {
  static const std::string aside = "aside:";
  if (into == "product") return move_parts(order, parts, Place::placed, "", "in_gripper");
  if (into.rfind(aside, 0) == 0 && into.size() > aside.size()) {
    return move_parts(order, parts, Place::placed, into.substr(aside.size()), "in_gripper");
  }
  move_parts(order, parts, Place::on_station, "", "in_gripper");
}

void CellStore::set_aside(const std::string& order, const std::string& part) {
  move_parts(order, {part}, Place::inspection, "", "in_gripper");
}

void CellStore::assemble(const std::string& order) {
  Transaction t(*this);
  Statement(db_, "UPDATE parts SET place = 'assembled', holder = '' WHERE order_id = ? AND place IN ('on_station', 'placed')")
      .bind(order)
      .step();
  t.commit();
}

std::vector<PartRecord> CellStore::parts_held(const std::string& holder, Place place) const {
  Statement rows(db_, "SELECT order_id, part, part_type, buffer, station FROM parts WHERE holder = ? AND place = ? "
                      "ORDER BY order_id, part");
  rows.bind(holder, place_name(place));
  std::vector<PartRecord> out;
  while (rows.step()) out.push_back({rows.text(0), rows.text(1), rows.text(2), rows.text(3), holder, place, rows.text(4)});
  return out;
}

std::vector<PartRecord> CellStore::return_carried(const std::string& carrier) {
  Transaction t(*this);
  const std::vector<PartRecord> carried = parts_held(carrier, Place::in_transit);
  for (const auto& p : carried) put_back(p);
  t.commit();
  return carried;
}

std::vector<PartRecord> CellStore::hold_for_inspection(const std::string& holder) {
  Transaction t(*this);
  const std::vector<PartRecord> held = parts_held(holder, Place::in_gripper);
  for (const auto& p : held) {
    Statement(db_, "UPDATE parts SET place = 'inspection' WHERE order_id = ? AND part = ?").bind(p.order, p.part).step();
  }
  t.commit();
  return held;
}

std::map<std::string, PartCount> CellStore::inventory() const {
  Transaction t(*this, "BEGIN");  // one snapshot for both tables
  std::map<std::string, PartCount> out;
  Statement stock(db_, "SELECT part_type, SUM(initial), SUM(count) FROM stock GROUP BY part_type");
  while (stock.step()) {
    PartCount& c = out[stock.text(0)];
    c.initial = static_cast<int>(stock.integer(1));
    c.in_buffers = static_cast<int>(stock.integer(2));
  }
  Statement parts(db_, "SELECT part_type, place, COUNT(*) FROM parts WHERE place != 'returned' GROUP BY part_type, place");
  while (parts.step()) {
    PartCount& c = out[parts.text(0)];
    const int n = static_cast<int>(parts.integer(2));
    switch (place_of(parts.text(1))) {
      case Place::in_transit: c.in_transit += n; break;
      case Place::on_station:
      case Place::in_gripper:
      case Place::placed: c.on_stations += n; break;
      case Place::assembled: c.assembled += n; break;
      case Place::inspection: c.inspection += n; break;
      case Place::returned: break;
    }
  }
  t.commit();
  return out;
}

std::vector<PartRecord> CellStore::parts(const std::string& order) const {
  Statement rows(db_, "SELECT order_id, part, part_type, buffer, place, holder, station FROM parts "
                      "WHERE ? = '' OR order_id = ? ORDER BY order_id, part");
  rows.bind(order, order);
  std::vector<PartRecord> out;
  while (rows.step()) {
    out.push_back({rows.text(0), rows.text(1), rows.text(2), rows.text(3), rows.text(5), place_of(rows.text(4)),
                   rows.text(6)});
  }
  return out;
}

void CellStore::command_taken(const CommandRecord& c) {
  Statement(db_, "INSERT OR REPLACE INTO commands(resource, command_id, order_id, operation, part) VALUES(?, ?, ?, ?, ?)")
      .bind(c.resource, c.command_id, c.order, c.operation, c.part)
      .step();
}

void CellStore::command_ended(const std::string& resource, const std::string& command_id) {
  Statement(db_, "DELETE FROM commands WHERE resource = ? AND command_id = ?").bind(resource, command_id).step();
}

std::vector<CommandRecord> CellStore::take_interrupted(const std::string& resource) {
  Transaction t(*this);
  Statement row(db_, "SELECT command_id, order_id, operation, part FROM commands WHERE resource = ? ORDER BY rowid");
  row.bind(resource);
  std::vector<CommandRecord> out;
  while (row.step()) out.push_back({resource, row.text(0), row.text(1), row.text(2), row.text(3)});
  Statement(db_, "DELETE FROM commands WHERE resource = ?").bind(resource).step();
  t.commit();
  return out;
}

std::vector<CommandRecord> CellStore::commands_of(const std::string& order) const {
  Statement rows(db_, "SELECT resource, command_id, operation, part FROM commands WHERE order_id = ?");
  rows.bind(order);
  std::vector<CommandRecord> out;
  while (rows.step()) out.push_back({rows.text(0), rows.text(1), order, rows.text(2), rows.text(3)});
  return out;
}

void CellStore::set_bookings(const std::string& resource, const std::vector<BookingRecord>& bookings) {
  Transaction t(*this);
  Statement(db_, "DELETE FROM bookings WHERE resource = ?").bind(resource).step();
  for (std::size_t i = 0; i < bookings.size(); ++i) {
    const BookingRecord& b = bookings[i];
    for (const auto& call : b.calls) {
      Statement(db_, "INSERT INTO bookings(resource, position, order_id, holds, duration, call_id) VALUES(?, ?, ?, ?, ?, ?)")
          .bind(resource, static_cast<long>(i), b.order, b.holds ? 1 : 0, b.duration, call)
          .step();
    }
  }
  t.commit();
}

std::vector<BookingRecord> CellStore::bookings(const std::string& resource) const {
  Statement rows(db_, "SELECT position, order_id, holds, duration, call_id FROM bookings WHERE resource = ? "
                      "ORDER BY position, call_id");
  rows.bind(resource);
  std::vector<BookingRecord> out;
  long position = -1;
  while (rows.step()) {
    if (rows.integer(0) != position) {
      position = rows.integer(0);
      out.push_back({rows.text(1), {}, rows.real(3), rows.integer(2) != 0});
    }
    out.back().calls.push_back(rows.text(4));
  }
  return out;
}

std::map<std::string, std::string> CellStore::holders() const {
  Statement rows(db_, "SELECT DISTINCT resource, order_id FROM bookings WHERE holds = 1");
  std::map<std::string, std::string> out;
  while (rows.step()) out[rows.text(0)] = rows.text(1);
  return out;
}

bool CellStore::submit_order(const OrderRecord& o) {
  Statement(db_, "INSERT OR IGNORE INTO orders(order_id, state, updated, product, out_dir, sequence, path_planner, quote, "
                 "client, request) VALUES(?, 'SUBMITTED', ?, ?, ?, ?, ?, ?, ?, ?)")
      .bind(o.order, unix_now(), o.product, o.out, o.sequence, o.path, o.quote ? 1 : 0, o.client, o.request)
      .step();
  return sqlite3_changes(db_) == 1;
}

void CellStore::set_order(const std::string& order, const std::string& state, const std::string& reason, int exit_code) {
  Statement(db_, "INSERT INTO orders(order_id, state, reason, updated, exit_code) VALUES(?, ?, ?, ?, NULLIF(?, -1)) "
                 "ON CONFLICT(order_id) DO UPDATE SET state = excluded.state, reason = excluded.reason, "
                 "updated = excluded.updated, exit_code = excluded.exit_code")
      .bind(order, state, reason, unix_now(), exit_code)
      .step();
}

void CellStore::set_order(const std::string& order, const std::string& state, const std::string& reason, int exit_code,
                          const JournalLine& line) {
  Transaction t(*this);
  set_order(order, state, reason, exit_code);
  journal(line.source, line.event, order, line.detail);
  t.commit();
}

bool CellStore::request_cancel(const std::string& order, const std::string& who) {
  Statement(db_, "UPDATE orders SET cancelled_by = ? WHERE order_id = ? AND state NOT IN ('DONE', 'FAILED')")
      .bind(who, order)
      .step();
  return sqlite3_changes(db_) > 0;
}

std::string CellStore::cancel_requested(const std::string& order) const {
  Statement row(db_, "SELECT cancelled_by FROM orders WHERE order_id = ?");
  row.bind(order);
  return row.step() ? row.text(0) : "";
}

void CellStore::set_out_of_service(const std::string& resource, const std::string& reason, const std::string& by) {
  if (reason.empty()) {
    Statement(db_, "DELETE FROM out_of_service WHERE resource = ?").bind(resource).step();
    return;
  }
  Statement(db_, "INSERT INTO out_of_service(resource, reason, by, since) VALUES(?, ?, ?, ?) "
                 "ON CONFLICT(resource) DO UPDATE SET reason = excluded.reason, by = excluded.by, since = excluded.since")
      .bind(resource, reason, by, unix_now())
      .step();
}

std::map<std::string, ServiceRecord> CellStore::out_of_service() const {
  std::map<std::string, ServiceRecord> out;
  Statement rows(db_, "SELECT resource, reason, by, since FROM out_of_service");
  while (rows.step()) out[rows.text(0)] = {rows.text(1), rows.text(2), rows.real(3)};
  return out;
}

int CellStore::count_attempt(const std::string& order) {
  Transaction t(*this);
  Statement(db_, "UPDATE orders SET attempts = attempts + 1 WHERE order_id = ?").bind(order).step();
  Statement n(db_, "SELECT attempts FROM orders WHERE order_id = ?");
  n.bind(order);
  const int attempts = n.step() ? static_cast<int>(n.integer(0)) : 0;
  t.commit();
  return attempts;
}

std::vector<OrderRecord> CellStore::orders() const {
  Statement rows(db_, "SELECT order_id, state, reason, product, out_dir, sequence, path_planner, IFNULL(exit_code, -1), "
                      "attempts, quote, client, request, rowid, cancelled_by FROM orders ORDER BY rowid");
  std::vector<OrderRecord> out;
  while (rows.step()) {
    out.push_back({rows.text(0), rows.text(1), rows.text(2), rows.text(3), rows.text(4), rows.text(5), rows.text(6),
                   static_cast<int>(rows.integer(7)), static_cast<int>(rows.integer(8)), rows.integer(9) != 0,
                   rows.text(10), rows.text(11), rows.integer(12), rows.text(13)});
  }
  return out;
}

void CellStore::set_plan(const std::string& order, const std::vector<PlanStepRecord>& steps) {
  Transaction t(*this);
  Statement(db_, "DELETE FROM plan_steps WHERE order_id = ?").bind(order).step();
  for (std::size_t i = 0; i < steps.size(); ++i) {
    Statement(db_, "INSERT INTO plan_steps(order_id, position, step, trajectory) VALUES(?, ?, ?, ?)")
        .bind(order, static_cast<long>(i), steps[i].step, steps[i].trajectory)
        .step();
  }
  t.commit();
}

std::vector<PlanStepRecord> CellStore::plan_of(const std::string& order) const {
  Statement rows(db_, "SELECT step, trajectory FROM plan_steps WHERE order_id = ? ORDER BY position");
  rows.bind(order);
  std::vector<PlanStepRecord> out;
  while (rows.step()) out.push_back({rows.text(0), rows.text(1)});
  return out;
}

bool CellStore::awaits_twin(const std::string& order) const {
  Statement row(db_, "SELECT state, product FROM orders WHERE order_id = ?");
  row.bind(order);
  if (!row.step()) return false;
  const std::string state = row.text(0);
  return state != "DONE" && state != "FAILED" && !row.text(1).empty();
}

bool OrderRecord::ended() const { return state == "DONE" || state == "FAILED"; }

void CellStore::journal(const std::string& source, const std::string& event, const std::string& order,
                        const std::string& detail) {
  Statement(db_, "INSERT INTO journal(time, source, event, order_id, detail) VALUES(?, ?, ?, ?, ?)")
      .bind(unix_now(), source, event, order, detail)
      .step();
}

std::vector<JournalEntry> CellStore::journal_since(long seq) const {
  Statement rows(db_, "SELECT seq, time, source, event, order_id, detail FROM journal WHERE seq > ? ORDER BY seq");
  rows.bind(seq);
  std::vector<JournalEntry> out;
  while (rows.step()) out.push_back({rows.integer(0), rows.real(1), rows.text(2), rows.text(3), rows.text(4), rows.text(5)});
  return out;
}

int CellStore::count_events(const std::string& source, const std::string& event) const {
  Statement n(db_, "SELECT COUNT(*) FROM journal WHERE source = ? AND event = ?");
  n.bind(source, event).step();
  return static_cast<int>(n.integer(0));
}

std::string CellStore::integrity() const {
  Statement check(db_, "PRAGMA integrity_check");
  std::string out;
  while (check.step()) out += (out.empty() ? "" : "; ") + check.text(0);
  return out;
}

}  // namespace state
