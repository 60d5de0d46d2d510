#pragma once
// IEC 61499 communication service blocks bound to DDS topics. The mapping between event
// data and the topic's type is the block's only knowledge of the type, given by the
// service that uses it; the runtime stays free of DDS.
//
//   PublishBlock:   REQ (data) -> writes one sample -> CNF, or ERROR (reason). A sample a
//                   slow reader has no room for yet is kept and written when there is (Outbox).
//   SubscribeBlock: a sample arrives -> IND (data); its writers are gone -> GONE (key data).
//                   A mapping that returns no data drops the sample on the listener thread
//                   (one meant for another resource never takes a place in this queue).
//                   A sample the resource's queue has no room for goes to `on_refused`
//                   (on the listener thread), which answers its sender.
//   RoutedPublishBlock: REQ (data) -> writes one sample on the topic `route` names for the
//                   data (a resource's own command topic), a writer per topic, made on first use;
//                   PREPARE (data) makes the writer ahead of use, so that it is matched by then
//                   (a match takes milliseconds, tens under load: sim seconds that the first
//                   command of an order would otherwise wait).

#include <functional>
#include <iostream>
#include <map>
#include <memory>

#include "services/dds/endpoints.hpp"
#include "services/runtime/resource.hpp"

namespace dds {

template <class T, class PubSubType>
class PublishBlock : public fb::FunctionBlock {
 public:
  using ToSample = std::function<T(const fb::Data&)>;

  PublishBlock(std::string name, ParticipantPtr participant, const std::string& topic, TopicKind kind, ToSample to_sample,
               const QosSettings& settings = {})
      : FunctionBlock(std::move(name)),
        writer_(std::make_unique<Outbox<T, PubSubType>>(std::move(participant), topic, kind, settings)),
        to_sample_(std::move(to_sample)) {
    declare_input("REQ");
    declare_output("CNF");
    declare_output("ERROR", {"reason"});
  }

  Writer<T, PubSubType>& writer() { return writer_->writer(); }

  void idle() override { writer_->flush(); }

  void receive(const fb::Event& event) override {
    if (event.name != "REQ") return;
    try {
      if (writer_->write(to_sample_(event.data))) return emit("CNF");
      emit("ERROR", {{"reason", name() + ": its readers have not taken the samples kept for them"}});
    } catch (const std::exception& e) {  // data that does not fit the type (a text too long)
      emit("ERROR", {{"reason", name() + ": " + e.what()}});
    }
  }

 private:
  std::unique_ptr<Outbox<T, PubSubType>> writer_;
  ToSample to_sample_;
};

template <class T, class PubSubType>
class SubscribeBlock : public fb::FunctionBlock {
 public:
  using ToData = std::function<fb::Data(const T&)>;

  SubscribeBlock(std::string name, ParticipantPtr participant, std::string topic, TopicKind kind, ToData to_data,
                 QosSettings settings = {})
      : FunctionBlock(std::move(name)), participant_(std::move(participant)), topic_(std::move(topic)), kind_(kind),
        to_data_(std::move(to_data)), settings_(settings) {
    declare_input("RECEIVED");  // from the DDS listener thread, through the resource's queue
    declare_input("LOST");
    declare_output("IND");
    declare_output("GONE");
  }

  // Starts listening; call once the block is on its resource and wired.
  void start() {
    reader_ = std::make_unique<Reader<T, PubSubType>>(
        participant_, topic_, kind_, [this](const T& s) { deliver("RECEIVED", s); },
        [this](const T& s) { deliver("LOST", s); }, settings_, speaker_);
  }

  void receive(const fb::Event& event) override {
    if (event.name == "RECEIVED") emit("IND", event.data);
    if (event.name == "LOST") emit("GONE", event.data);
  }

  // Set before start().
  void on_refused(std::function<void(const T&, const std::string& why)> refused) { on_refused_ = std::move(refused); }
  // Set before start(): samples count only from a writer that speaks for that resource (Reader).
  void written_by(Speaker<T> speaker) { speaker_ = std::move(speaker); }

 private:
  void deliver(const char* input, const T& sample) {
    try {
      fb::Data data = to_data_(sample);
      if (data.empty()) return;
      post_to_self(input, std::move(data));
    } catch (const fb::EventQueueOverflow& e) {
      if (on_refused_) {
        try {
          on_refused_(sample, "queue full");
        } catch (const std::exception& answer) {
          std::cerr << "error: " << name() << " on " << topic_ << ": " << answer.what() << '\n';
        }
      }
    } catch (const std::exception& e) {
      // Nothing to return to on a listener thread: say it loudly; the resource counts it.
      std::cerr << "error: " << name() << " on " << topic_ << ": " << e.what() << '\n';
    }
  }

  ParticipantPtr participant_;
  std::string topic_;
  TopicKind kind_;
  ToData to_data_;
  QosSettings settings_;
  std::function<void(const T&, const std::string&)> on_refused_;
  Speaker<T> speaker_;
  std::unique_ptr<Reader<T, PubSubType>> reader_;
};

template <class T, class PubSubType>
class RoutedPublishBlock : public fb::FunctionBlock {
 public:
  using ToSample = std::function<T(const fb::Data&)>;
  using Route = std::function<std::string(const fb::Data&)>;  // the topic for the data

  RoutedPublishBlock(std::string name, ParticipantPtr participant, Route route, ToSample to_sample,
                     QosSettings settings = {})
      : FunctionBlock(std::move(name)), participant_(std::move(participant)), route_(std::move(route)),
        to_sample_(std::move(to_sample)), settings_(settings) {
    declare_input("REQ");
    declare_input("PREPARE");
    declare_output("CNF");
    declare_output("ERROR", {"reason"});
  }

  void receive(const fb::Event& event) override {
    if (event.name != "REQ" && event.name != "PREPARE") return;
    try {
      const std::string topic = route_(event.data);
      Topic& route = writers_[topic];
      if (!route.writer) route.writer = std::make_unique<Writer<T, PubSubType>>(participant_, topic, TopicKind::events, settings_);
      if (event.name == "PREPARE") return;
      if (!route.used) {
        // The reader is there (its resource was hired): wait for the match, which takes
        // milliseconds between participants that know each other, so the first sample is not
        // lost. A writer prepared in time is matched already.
        route.writer->wait_for_readers(1, std::chrono::seconds(1));
        route.used = true;
      }
      if (route.writer->write(to_sample_(event.data))) return emit("CNF");
      emit("ERROR", {{"reason", std::string("DDS write failed on ") + topic}});
    } catch (const std::exception& e) {
      emit("ERROR", {{"reason", std::string(e.what())}});
    }
  }

 private:
  ParticipantPtr participant_;
  Route route_;
  ToSample to_sample_;
  QosSettings settings_;
  struct Topic {
    std::unique_ptr<Writer<T, PubSubType>> writer;
    bool used = false;  // a sample was written
  };
  std::map<std::string, Topic> writers_;
};

}  // namespace dds
