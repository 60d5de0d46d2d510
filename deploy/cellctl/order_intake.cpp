#include "deploy/cellctl/order_intake.hpp"

#include <openssl/rand.h>

#include <algorithm>
#include <vector>

#include "deploy/cellctl/product_archive.hpp"
#include "twin/description/automationml/automationml_description.hpp"
#include "twin/description/product_description.hpp"

namespace cellctl {
namespace fs = std::filesystem;

std::string random_hex(std::size_t bytes) {
  std::vector<unsigned char> random(bytes);
  if (RAND_bytes(random.data(), static_cast<int>(bytes)) != 1) throw std::runtime_error("no random bytes to be had");
  static const char* hex = "0123456789abcdef";
  std::string text;
  for (unsigned char b : random) {
    text += hex[b >> 4];
    text += hex[b & 15];
  }
  return text;
}

bool good_order_id(const std::string& id) {
  return !id.empty() && id.size() <= 64 &&
         id.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._-") == std::string::npos &&
         id.front() != '.';
}

std::string relative_to(std::string message, const fs::path& folder) {
  const std::string prefix = folder.string() + "/";
  for (auto at = message.find(prefix); at != std::string::npos; at = message.find(prefix)) message.erase(at, prefix.size());
  return message;
}

std::string description_error(const fs::path& aml, const fs::path& folder) {
  try {
    twin::build_product(twin::AutomationMLDescription(aml));
    return "";
  } catch (const twin::DescriptionError& e) {
    return relative_to(e.what(), folder);
  }
}

UploadAnswer take_upload(const CellConfig& cell, state::CellStore& store, std::string_view zip, std::string order,
                         const std::string& who) {
  if (order.empty()) order = "upload-" + random_hex(4);
  if (!good_order_id(order)) return {400, "", "an order's id is 1 to 64 of A-Z, a-z, 0-9, ., _ and -"};
  const auto orders = store.orders();
  const auto under_way = std::count_if(orders.begin(), orders.end(), [](const auto& o) { return !o.ended(); });
  if (under_way >= cell.desk.max_orders) {
    return {503, "", "the cell has " + std::to_string(under_way) +
                         " orders queued or under way, its limit (desk: max_orders); try again later"};
  }
  if (std::any_of(orders.begin(), orders.end(), [&](const auto& o) { return o.order == order; })) {
    return {409, "", "the cell has an order " + order + " already: give this one another id"};
  }
  const fs::path folder = cell.state_folder() / "uploads" / order;
  std::error_code ignored;
  fs::remove_all(folder, ignored);  // left by an upload that a crash cut short: no order names it
  fs::path aml;
  try {
    aml = unpack_product(zip, folder / "product",
                         {static_cast<std::uint64_t>(cell.desk.max_order_mb * 1e6), ArchiveLimits{}.max_entries});
  } catch (const ArchiveError& e) {
    fs::remove_all(folder, ignored);
    return {400, "", e.what()};
  }
  const auto refuse = [&](int status, const std::string& why) {
    fs::remove_all(folder, ignored);
    return UploadAnswer{status, "", why};
  };
  try {
    if (const std::string error = description_error(aml, folder / "product"); !error.empty()) return refuse(400, error);
    fs::create_directories(folder / "out");
    state::OrderRecord record{order, "", "", aml.string(), (folder / "out").string(), "search", "linear"};
    if (!store.submit_order(record)) return refuse(409, "the cell has an order " + order + " already: give this one another id");
  } catch (...) {
    refuse(500, "");
    throw;
  }
  const std::string product = aml.lexically_relative(folder / "product").string();
  store.journal(who, "submitted", order, product + ", " + std::to_string(zip.size()) + " bytes uploaded");
  return {200, order, "order " + order + " (" + product + ") handed to the cell"};
}

ActionAnswer cancel_order(state::CellStore& store, const std::string& order, const std::string& who) {
  const auto orders = store.orders();
  const auto o = std::find_if(orders.begin(), orders.end(), [&](const auto& r) { return r.order == order; });
  if (o == orders.end()) return {404, "the cell has no order " + order};
  if (o->ended() || !store.request_cancel(order, who)) {
    return {409, "order " + order + " has ended (" + o->state + "): there is nothing to cancel"};
  }
  store.journal(who, "cancel asked", order);
  return {200, "cancel of order " + order + " asked: " +
                   (o->attempts == 0 ? "it never starts" : "its twin fails it and cleans up within seconds")};
}

}  // namespace cellctl
