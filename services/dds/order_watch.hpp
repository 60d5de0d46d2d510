#pragma once
// The orders' status topic bound to an OrderWatch block on a resource: blocks "orders"
// (subscribe) and "order_watch", wired. Connect order_watch's ENDED (and ACTIVE) where they
// are needed, then start() the returned block.

#include "ordersPubSubTypes.h"
#include "services/blocks/order_watch.hpp"
#include "services/dds/service_blocks.hpp"

namespace dds {

using OrderStatusSubscriber = SubscribeBlock<cell::OrderStatus, cell::OrderStatusPubSubType>;

inline OrderStatusSubscriber& watch_orders(fb::Resource& resource, const ParticipantPtr& participant,
                                           fb::OrderWatch::Resumable resumable = {}) {
  auto& orders = resource.add(std::make_unique<OrderStatusSubscriber>(
      "orders", participant, "cell/orders/status", TopicKind::state, [](const cell::OrderStatus& s) {
        return fb::Data{{"order_id", s.order_id().to_string()}, {"ended", s.state() == cell::DONE || s.state() == cell::FAILED}};
      }));
  resource.add(std::make_unique<fb::OrderWatch>(std::move(resumable)));
  resource.connect("orders", "IND", "order_watch", "STATUS");
  resource.connect("orders", "GONE", "order_watch", "GONE");
  return orders;
}

}  // namespace dds
