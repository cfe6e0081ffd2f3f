#include "framework/runtime.h"

#include <atomic>
#include <chrono>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include <oneapi/tbb/flow_graph.h>

#include "framework/frame_admission.h"
#include "framework/keyed_join.h"
#include "framework/latency_histogram.h"
#include "framework/nearest_names.h"
#include "framework/sequence_reorder.h"
#include "framework/thread_sanitizer.h"
#include "tilth/log.h"

namespace tilth {
namespace {

std::int64_t steady_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::int64_t host_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

struct Node {
  ResolvedNode spec;
  StageInstance instance;
  Source* source = nullptr;
  Transform* transform = nullptr;
  Sink* sink = nullptr;
  Synchronizer* synchronizer = nullptr;
  std::optional<std::size_t> synchronized_by;  // a source: the synchronizer it feeds
  std::size_t admission_slot = 0;              // a source or synchronizer: its FrameAdmission slot
  std::size_t sources_ended = 0;               // a synchronizer: its sources whose streams ended
  std::vector<std::size_t> predecessors;       // distinct node indices
  // Per input port: (predecessor slot, its output port), or none for an unconnected
  // optional input.
  std::vector<std::optional<std::pair<std::size_t, std::size_t>>> input_of;
  std::unique_ptr<KeyedJoin> join;
  bool ordered = false;
  std::mutex order_mutex;  // also serialises a synchronizer's accept() and its offers
  SequenceReorder<std::vector<BundlePtr>> reorder;
  // Bundles travel through this inbox, under its mutex, and the flow graph carries one
  // token per bundle: the hand-over between threads is then visible to ThreadSanitizer,
  // which cannot see inside libtbb.
  std::mutex inbox_mutex;
  std::deque<BundlePtr> inbox;
  std::unique_ptr<tbb::flow::function_node<tbb::flow::continue_msg>> flow_node;
  LatencyHistogram latency;
  std::atomic<std::uint64_t> errors{0};
  std::atomic<std::uint64_t> skipped{0};
  std::mutex loss_mutex;
  std::optional<DataLoss> loss;

  void add_delivery(BundlePtr bundle) {
    std::lock_guard lock(inbox_mutex);
    inbox.push_back(std::move(bundle));
  }
  BundlePtr take_delivery() {
    std::lock_guard lock(inbox_mutex);
    BundlePtr bundle = std::move(inbox.front());
    inbox.pop_front();
    return bundle;
  }

  const std::string& type() const { return spec.stage->descriptor.type; }
  std::string label() const { return "node '" + spec.name + "' (" + type() + ")"; }
};

// The frames a synchronizer emits during one accept() call.
class EmittedFrames final : public Synchronizer::Output {
 public:
  EmittedFrames(std::size_t node, std::size_t outputs) : node_(node), outputs_(outputs) {}

  Frame& emit() override {
    auto bundle = std::make_shared<Bundle>();
    bundle->node = node_;
    bundle->outputs.resize(outputs_);
    frames_.emplace_back(FrameInfo{}, std::span<const Packet>{}, bundle->outputs);
    bundles_.push_back(std::move(bundle));
    return frames_.back();
  }

  // The bundles, each with the capture identity set on its Frame.
  std::vector<std::shared_ptr<Bundle>> take() {
    for (std::size_t i = 0; i < bundles_.size(); ++i) bundles_[i]->info = frames_[i].info();
    return std::move(bundles_);
  }

 private:
  const std::size_t node_;
  const std::size_t outputs_;
  std::deque<Frame> frames_;  // a deque: emit() hands out references that must stay valid
  std::vector<std::shared_ptr<Bundle>> bundles_;
};

}  // namespace

class Runtime::Impl {
 public:
  Impl(ValidatedGraph graph, const StageRegistry& registry, RunLimits limits)
      : graph_(std::move(graph)), limits_(limits) {
    if (!graph_.open_inputs.empty()) {
      throw Error("a fragment: nothing feeds its inputs " + quoted_list(graph_.open_inputs) +
                  "; run a graph that includes it and feeds them (docs/graph-format.md)");
    }
    make_stages(registry);
    wire();
    admission_ = std::make_unique<FrameAdmission>(
        admission_slots_, graph_.runtime.max_in_flight, graph_.runtime.when_full,
        [this](std::uint64_t sequence, std::vector<std::shared_ptr<Bundle>> bundles) {
          admit(sequence, std::move(bundles));
        },
        limits_.max_frames);
    constructed_.store(true, std::memory_order_release);
  }

  RunResult run() {
    // This thread works in the flow graph's arena (wait_for_all) until every admitted
    // frame is done; the reservation keeps it there while sources may still admit.
    flow_.reserve_wait();
    publish_graph_to_workers();
    std::vector<std::thread> threads;
    threads.emplace_back([this] {
      admission_->wait_until_drained();
      flow_.release_wait();
    });
    for (std::size_t s = 0; s < sources_.size(); ++s) {
      threads.emplace_back([this, s] { pump(s); });
    }
    flow_.wait_for_all();
    admission_->wait_until_drained();
    interrupt_sources();
    for (auto& thread : threads) thread.join();
    flow_.wait_for_all();
    finish_stages();
    RunResult result;
    result.metrics = metrics();
    result.stopped = stop_requested_;
    for (auto& node : nodes_) {
      std::lock_guard lock(node->loss_mutex);
      if (node->loss) result.data_lost.push_back(*node->loss);
    }
    std::lock_guard lock(failure_mutex_);
    result.failed = failed_;
    result.failure = failure_;
    return result;
  }

  void request_stop() {
    stop_requested_ = true;
    stop();
  }

  void stop() {
    stopping_ = true;
    admission_->close();
    interrupt_sources();
  }

  // Empty while the stages are still being made: a stage may ask from a thread of its own
  // (the live view's server) as soon as it exists.
  PipelineMetrics metrics() const {
    PipelineMetrics result;
    if (!constructed_.load(std::memory_order_acquire)) return result;
    for (const auto& node : nodes_) {
      result.stages.push_back({node->spec.name, node->type(), node->latency.summary(),
                               node->errors.load(), node->skipped.load()});
    }
    result.frames_admitted = admission_->admitted();
    result.frames_dropped = admission_->dropped();
    result.frames_in_flight = admission_->in_flight();
    result.end_to_end = end_to_end_.summary();
    std::lock_guard lock(done_mutex_);
    result.frames_completed = completed_;
    // From the first frame done: start-up (plugins, calibration, a camera's first frame)
    // is not part of the rate.
    if (completed_ > 1 && last_done_ns_ > first_done_ns_) {
      result.frames_per_second = static_cast<double>(completed_ - 1) /
                                 (static_cast<double>(last_done_ns_ - first_done_ns_) * 1e-9);
    }
    return result;
  }

 private:
  void make_stages(const StageRegistry& registry) {
    std::string failures;
    for (auto& spec : graph_.nodes) {
      auto node = std::make_unique<Node>();
      node->spec = std::move(spec);
      StageContext context{node->spec.name,
                           node->spec.params,
                           Logger(node->spec.name),
                           [this] { return metrics(); },
                           [this, lost = node.get()](std::uint64_t frames, const std::string& why) {
                             record_loss(*lost, frames, why);
                           },
                           [this, name = node->spec.name](const std::string& why) {
                             log(LogLevel::kWarning, name, "ending the run: " + why);
                             stop();
                           }};
      try {
        node->instance = registry.create(node->type(), context);
      } catch (const Error& failure) {
        failures += std::string(failures.empty() ? "" : "\n") + failure.what();
      }
      Stage* stage = node->instance.stage.get();
      node->source = dynamic_cast<Source*>(stage);
      node->transform = dynamic_cast<Transform*>(stage);
      node->sink = dynamic_cast<Sink*>(stage);
      node->synchronizer = dynamic_cast<Synchronizer*>(stage);
      const StageKind kind = node->spec.stage->descriptor.kind();
      const bool matches = (kind == StageKind::kSource && node->source) ||
                           (kind == StageKind::kTransform && node->transform) ||
                           (kind == StageKind::kSink && node->sink) ||
                           (kind == StageKind::kSynchronizer && node->synchronizer);
      if (stage != nullptr && !matches) {
        failures += std::string(failures.empty() ? "" : "\n") + node->label() +
                    ": the stage object is not a " + std::string(to_string(kind)) +
                    " although its ports make it one";
      }
      nodes_.push_back(std::move(node));
    }
    if (!failures.empty()) throw Error(failures);
  }

  void wire() {
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
      Node& node = *nodes_[i];
      if (node.source) sources_.push_back(i);
      if (node.spec.successors.empty()) ++terminal_count_;
      for (const auto& input : node.spec.inputs) {
        if (!input) {
          node.input_of.emplace_back();
          continue;
        }
        auto slot = std::find(node.predecessors.begin(), node.predecessors.end(), input->node);
        if (slot == node.predecessors.end()) {
          node.predecessors.push_back(input->node);
          slot = node.predecessors.end() - 1;
        }
        node.input_of.emplace_back(
            std::pair<std::size_t, std::size_t>(slot - node.predecessors.begin(), input->port));
      }
      if (node.synchronizer) {
        for (std::size_t from : node.predecessors) nodes_[from]->synchronized_by = i;
      }
      if (node.source || node.synchronizer) continue;
      node.join = std::make_unique<KeyedJoin>(node.predecessors.size());
      node.ordered = node.sink || node.spec.stage->descriptor.concurrency == Concurrency::kSerial;
      node.flow_node = std::make_unique<tbb::flow::function_node<tbb::flow::continue_msg>>(
          flow_, node.ordered ? tbb::flow::serial : tbb::flow::unlimited,
          [this, i](tbb::flow::continue_msg) {
            acquire_published_graph();
            receive(i, nodes_[i]->take_delivery());
            return tbb::flow::continue_msg();
          });
    }
    // Frames enter the graph at sources, except where a synchronizer lines sources up.
    for (auto& node : nodes_) {
      if ((node->source && !node->synchronized_by) || node->synchronizer) {
        node->admission_slot = admission_slots_++;
      }
    }
  }

  // A source's thread: produce, stamp, offer (or hand to its synchronizer), until the
  // stream ends or the graph stops.
  void pump(std::size_t source_index) {
    const std::size_t index = sources_[source_index];
    Node& node = *nodes_[index];
    const std::size_t outputs = node.spec.stage->descriptor.outputs.size();
    while (!stopping_) {
      auto bundle = std::make_shared<Bundle>();
      bundle->node = index;
      bundle->outputs.resize(outputs);
      Frame frame(FrameInfo{}, {}, bundle->outputs);
      bool more = false;
      const std::int64_t begin = steady_now_ns();
      try {
        more = node.source->produce(frame);
      } catch (const std::exception& failure) {
        ++node.errors;
        fail(node.label() + " failed: " + failure.what() + "; its stream ends here", true);
      }
      if (!more) break;
      node.latency.record(steady_now_ns() - begin);
      bundle->info = frame.info();
      if (bundle->info.host_timestamp_ns == 0) bundle->info.host_timestamp_ns = host_now_ns();
      const bool open = node.synchronized_by
                            ? synchronize(*node.synchronized_by, std::move(bundle))
                            : admission_->offer(node.admission_slot, std::move(bundle));
      if (!open) break;
    }
    if (node.synchronized_by) {
      end_synchronized_stream(*node.synchronized_by);
    } else {
      admission_->end_of_stream(node.admission_slot);
    }
  }

  // A synchronizer's stream ends with the last of its sources' streams.
  void end_synchronized_stream(std::size_t index) {
    Node& node = *nodes_[index];
    std::lock_guard lock(node.order_mutex);
    if (++node.sources_ended == node.predecessors.size()) {
      admission_->end_of_stream(node.admission_slot);
    }
  }

  // Hands one source frame to a synchronizer and offers what it emits; false once
  // admission is closed.
  bool synchronize(std::size_t index, BundlePtr arrived) {
    Node& node = *nodes_[index];
    std::lock_guard lock(node.order_mutex);
    std::vector<Packet> inputs(node.input_of.size());
    for (std::size_t p = 0; p < inputs.size(); ++p) {
      const auto& from = node.input_of[p];
      if (from && node.predecessors[from->first] == arrived->node) {
        inputs[p] = arrived->outputs[from->second];
      }
    }
    const Frame frame(arrived->info, inputs, {});
    EmittedFrames emitted(index, node.spec.stage->descriptor.outputs.size());
    const std::int64_t begin = steady_now_ns();
    const bool ok =
        call_guarded(node, arrived->info, [&] { node.synchronizer->accept(frame, emitted); });
    node.latency.record(steady_now_ns() - begin);
    if (!ok) return !stopping_;
    for (auto& bundle : emitted.take()) {
      if (bundle->info.host_timestamp_ns == 0) bundle->info.host_timestamp_ns = host_now_ns();
      if (!admission_->offer(node.admission_slot, std::move(bundle))) return false;
    }
    return true;
  }

  void admit(std::uint64_t sequence, std::vector<std::shared_ptr<Bundle>> bundles) {
    {
      std::lock_guard lock(done_mutex_);
      remaining_[sequence] = terminal_count_;
    }
    for (auto& bundle : bundles) {
      bundle->info.sequence = sequence;
      for (auto& packet : bundle->outputs) {
        if (!packet.empty()) packet = Packet(bundle->info, packet.message());
      }
    }
    for (auto& bundle : bundles) {
      const std::size_t from = bundle->node;
      deliver(from, std::move(bundle));
    }
  }

  void deliver(std::size_t from, BundlePtr bundle) {
    const auto& successors = nodes_[from]->spec.successors;
    if (successors.empty()) {
      frame_done(bundle->info);
      return;
    }
    for (std::size_t next : successors) {
      nodes_[next]->add_delivery(bundle);
      nodes_[next]->flow_node->try_put(tbb::flow::continue_msg());
    }
  }

  void receive(std::size_t index, const BundlePtr& bundle) {
    Node& node = *nodes_[index];
    const std::size_t slot =
        std::find(node.predecessors.begin(), node.predecessors.end(), bundle->node) -
        node.predecessors.begin();
    auto complete = node.join->add(bundle->info.sequence, slot, bundle);
    if (!complete) return;
    if (!node.ordered) {
      execute(index, *complete);
      return;
    }
    std::lock_guard lock(node.order_mutex);
    for (auto& ready : node.reorder.push(bundle->info.sequence, std::move(*complete))) {
      execute(index, ready);
    }
  }

  void execute(std::size_t index, const std::vector<BundlePtr>& arrived) {
    Node& node = *nodes_[index];
    const FrameInfo info = arrived.front()->info;
    const auto& ports = node.spec.stage->descriptor.inputs;
    std::vector<Packet> inputs;
    bool missing = false;
    for (std::size_t p = 0; p < node.input_of.size(); ++p) {
      const auto& from = node.input_of[p];
      inputs.push_back(from ? arrived[from->first]->outputs[from->second] : Packet{});
      missing = missing || (ports[p].required && inputs.back().empty());
    }
    auto result = std::make_shared<Bundle>();
    result->node = index;
    result->info = info;
    result->outputs.resize(node.spec.stage->descriptor.outputs.size());
    if (missing) {
      ++node.skipped;
      if (node.sink) call_guarded(node, info, [&] { node.sink->skipped(info); });
    } else {
      Frame frame(info, inputs, result->outputs);
      const std::int64_t begin = steady_now_ns();
      const bool ok = call_guarded(node, info, [&] {
        if (node.transform) {
          node.transform->process(frame);
        } else {
          node.sink->consume(frame);
        }
      });
      node.latency.record(steady_now_ns() - begin);
      if (!ok) std::fill(result->outputs.begin(), result->outputs.end(), Packet{});
    }
    deliver(index, std::move(result));
  }

  template <class Call>
  bool call_guarded(Node& node, const FrameInfo& info, Call&& call) {
    std::string what;
    try {
      call();
      return true;
    } catch (const std::exception& failure) {
      what = failure.what();
    } catch (...) {
      what = "unknown exception";
    }
    ++node.errors;
    const std::string message = node.label() + " failed on frame " + std::to_string(info.frame_id) +
                                " (sequence " + std::to_string(info.sequence) + "): " + what;
    if (graph_.runtime.on_error == ErrorPolicy::kStop) {
      fail(message + "; stopping (on_error: stop)", true);
      stop();
    } else {
      log(LogLevel::kError, "runtime", message + "; frame skipped (on_error: skip)");
    }
    return false;
  }

  void fail(const std::string& message, bool log_it) {
    if (log_it) log(LogLevel::kError, "runtime", message);
    std::lock_guard lock(failure_mutex_);
    if (!failed_) failure_ = message;
    failed_ = true;
  }

  void record_loss(Node& node, std::uint64_t frames, const std::string& why) {
    std::lock_guard lock(node.loss_mutex);
    if (!node.loss) {
      node.loss = DataLoss{node.spec.name, node.type(), 0, why};
      log(LogLevel::kError, "runtime", node.label() + " lost data: " + why + "; the graph runs on");
    }
    node.loss->frames += frames;
  }

  void frame_done(const FrameInfo& info) {
    {
      std::lock_guard lock(done_mutex_);
      auto it = remaining_.find(info.sequence);
      if (--it->second > 0) return;
      remaining_.erase(it);
      last_done_ns_ = steady_now_ns();
      if (++completed_ == 1) first_done_ns_ = last_done_ns_;
    }
    end_to_end_.record(host_now_ns() - info.host_timestamp_ns);
    admission_->complete();
  }

  void interrupt_sources() {
    for (std::size_t s : sources_) nodes_[s]->source->interrupt();
  }

  void finish_stages() {
    for (auto& node : nodes_) {
      try {
        node->instance.stage->finish();
      } catch (const std::exception& failure) {
        ++node->errors;
        fail(node->label() + " failed to finish: " + failure.what(), true);
      }
    }
  }

  ValidatedGraph graph_;
  const RunLimits limits_;
  tbb::flow::graph flow_;  // before nodes_: outlives every flow node
  std::vector<std::unique_ptr<Node>> nodes_;
  std::vector<std::size_t> sources_;
  std::size_t admission_slots_ = 0;
  std::size_t terminal_count_ = 0;
  std::unique_ptr<FrameAdmission> admission_;
  std::atomic<bool> constructed_{false};  // nodes_ and admission_ are complete
  std::atomic<bool> stopping_{false};
  std::atomic<bool> stop_requested_{false};

  mutable std::mutex done_mutex_;
  std::map<std::uint64_t, std::size_t> remaining_;  // terminal nodes still to finish, per frame
  std::uint64_t completed_ = 0;
  std::int64_t first_done_ns_ = 0;
  std::int64_t last_done_ns_ = 0;
  LatencyHistogram end_to_end_;

  std::mutex failure_mutex_;
  bool failed_ = false;
  std::string failure_;
};

Runtime::Runtime(ValidatedGraph graph, const StageRegistry& registry, RunLimits limits)
    : impl_(std::make_unique<Impl>(std::move(graph), registry, limits)) {}
Runtime::~Runtime() = default;
RunResult Runtime::run() { return impl_->run(); }
void Runtime::stop() { impl_->request_stop(); }
PipelineMetrics Runtime::metrics() const { return impl_->metrics(); }

}  // namespace tilth
