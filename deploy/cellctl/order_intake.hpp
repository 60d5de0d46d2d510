#pragma once
// What every door of the cell's desk checks before an order is stored: the order's id, and
// the product's description read whole (the errors `cellctl submit` gives, relative to the
// product's folder: the sender knows its files by their names). The dashboard's door: a
// product uploaded as one zip (product_archive.hpp) becomes an order of the cell's. And the
// operator's cancel, from `cellctl cancel` and the dashboard alike.

#include <filesystem>
#include <string>
#include <string_view>

#include "deploy/cellctl/cell_config.hpp"
#include "services/state/cell_store.hpp"

namespace cellctl {

// `bytes` random bytes in hex: an id or a token no one guesses.
std::string random_hex(std::size_t bytes);

// 1 to 64 of A-Z, a-z, 0-9, '.', '_' and '-', not starting with '.'.
bool good_order_id(const std::string& id);

// `message` with "FOLDER/" taken out of every path in it.
std::string relative_to(std::string message, const std::filesystem::path& folder);

// Reads the description as a twin will; "" when it builds a product, else the error
// (file, line, element), its paths relative to `folder`.
std::string description_error(const std::filesystem::path& aml, const std::filesystem::path& folder);

struct UploadAnswer {
  int status = 200;     // as HTTP says it: 200 stored, 400 a bad upload, 409 the id is taken, 503 the cell is full
  std::string order;    // the order's id, when stored
  std::string message;  // what the operator reads
};

// Unpacks the zip into the state folder (uploads/ORDER/product), reads its description and
// stores the order for the cell's desk (the same record as `cellctl submit --detach`), with
// `who` in the journal. `order` may be "": an id is made. A refusal keeps nothing.
UploadAnswer take_upload(const CellConfig& cell, state::CellStore& store, std::string_view zip, std::string order,
                         const std::string& who);

// The answer to an operator's action (a cancel, a resource out of service or back).
struct ActionAnswer {
  int status = 200;  // as HTTP says it: 200 done or asked, 400 bad ask, 404 no such order or resource, 409 too late
  std::string message;
};

// Asks that the order be cancelled (CellStore::request_cancel), journalled with `who` ("the
// operator (dashboard)"): its reason will read "cancelled by WHO".
ActionAnswer cancel_order(state::CellStore& store, const std::string& order, const std::string& who);

}  // namespace cellctl
