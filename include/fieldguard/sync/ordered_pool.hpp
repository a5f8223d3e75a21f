#pragma once
// A worker pool behind a bounded lock-free queue, with results handed out in submission order.
//
//   producer (the io thread) --submit()--> [input queue, bounded] --> N workers --> [done queue] --> poll()
//
// Thread contract: submit()/try_submit() from ONE producer thread; poll()/poll_wait() from ONE consumer thread
// (may be the producer's); stop() from the owner once the producer has stopped submitting (idempotent); the
// destructor stops and joins. counters() and outstanding() may be read from any thread.
//
// - The producer never blocks: every job lives in a slot taken from a preallocated lock-free free list (a fixed-size
//   boost::lockfree::stack), the two queues are fixed-size boost::lockfree::queue, and results wait for their turn
//   in a ring of the slots.
//   The pool allocates nothing after construction: an input is swapped into its slot, and the caller gets the
//   slot's earlier input back to refill; a ProcessInto writes its result over the slot's earlier one, whose
//   buffers it may reuse.
// - A full input queue drops, by policy, the oldest queued input or the new one. A dropped input still takes its
//   place in the order: the consumer is told (Outcome::Dropped) when its turn comes, so a gap is never silent.
//   When every slot is in use (the consumer has fallen far behind) the new input is refused outright and counted
//   as `refused` (it never got a ticket).
// - A job whose processing throws is reported as Outcome::Failed with the exception's message.
// - stop(Drain::Yes) processes what is queued; stop(Drain::No) discards it (Outcome::Discarded). Either way the
//   consumer's next poll() hands out every remaining ticket, in order.
// - PoolParams::on_result tells the consumer that a result is ready, so that it need not poll on a timer.
// - Accounting, once stopped and polled empty: submitted = processed + failed + dropped + discarded (+ refused,
//   which never entered).

#include <atomic>
#include <boost/lockfree/policies.hpp>
#include <boost/lockfree/queue.hpp>
#include <boost/lockfree/stack.hpp>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "fieldguard/sync/threads.hpp"

namespace fieldguard::sync {

enum class DropPolicy : std::uint8_t { DropOldest, DropNewest };
enum class Drain : std::uint8_t { Yes, No };
enum class Outcome : std::uint8_t { Processed, Failed, Dropped, Discarded };
[[nodiscard]] constexpr const char* to_string(Outcome o) {
  switch (o) {
    case Outcome::Processed: return "processed";
    case Outcome::Failed: return "failed";
    case Outcome::Dropped: return "dropped";
    case Outcome::Discarded: return "discarded";
  }
  return "?";
}

struct PoolParams {
  std::size_t workers = 1;         // 1..64
  std::size_t queue_capacity = 8;  // inputs waiting for a worker, 1..4096
  std::size_t reorder_slack = 16;  // extra slots for results waiting for the consumer or for their turn
  DropPolicy drop = DropPolicy::DropOldest;
  // Called, when set, each time a result becomes ready for poll(): on the worker that finished the job (or on the
  // producer's or owner's thread for a drop or a discard). It must not block: the daemon posts a wake-up to its
  // io thread with it, so that a finished frame is decided at once instead of at the next timer tick.
  std::function<void()> on_result;
  // Each worker applies these to itself when it starts (name, scheduling, affinity: threads.hpp); what the
  // system refused is kept for thread_refusal().
  ThreadSettings worker;
};

struct PoolCounters {
  std::uint64_t submitted = 0;  // submit() calls that got a ticket
  std::uint64_t refused = 0;    // submit() calls that found no free slot (no ticket)
  std::uint64_t processed = 0;
  std::uint64_t failed = 0;
  std::uint64_t dropped = 0;    // full queue, by policy
  std::uint64_t discarded = 0;  // left in the queue by stop(Drain::No)
  std::uint64_t delivered = 0;  // tickets handed to the consumer
};

template <typename In, typename Out>
class OrderedPool {
 public:
  using Process = std::function<Out(In&)>;
  // The form that allocates nothing once warm: writes the result into `out`, the slot's output of an earlier ticket
  // (default-constructed the first time), whose buffers it may reuse; a throw leaves the slot without a result.
  using ProcessInto = std::function<void(In&, Out&)>;
  // One result per ticket, in ticket order. `output` is set for Processed only; `error` for Failed.
  struct Result {
    std::uint64_t ticket = 0;
    Outcome outcome = Outcome::Processed;
    In* input = nullptr;  // the input (for Dropped/Discarded: what was lost), valid during the callback
    Out* output = nullptr;
    const std::string* error = nullptr;
  };
  using Sink = std::function<void(const Result&)>;

  OrderedPool(const PoolParams& params, Process process)
      : OrderedPool(params, ProcessInto([p = std::move(process)](In& in, Out& out) { out = p(in); })) {}
  OrderedPool(const PoolParams& params, ProcessInto process)
      : params_(check(params)),
        process_(std::move(process)),
        slots_(params_.queue_capacity + params_.workers + params_.reorder_slack + 1),
        free_(slots_.size()),
        input_(params_.queue_capacity),
        done_(slots_.size()),
        waiting_(slots_.size(), nullptr) {
    for (Slot& s : slots_) release(&s);
    trim_scratch_.reserve(slots_.size());
    workers_.reserve(params_.workers);
    for (std::size_t i = 0; i < params_.workers; ++i) workers_.emplace_back([this] { work(); });
  }
  OrderedPool(const OrderedPool&) = delete;
  OrderedPool& operator=(const OrderedPool&) = delete;
  ~OrderedPool() { stop(Drain::No); }

  // Producer. Never blocks. Applies the drop policy when the queue is full. False when refused (no slot) or
  // stopped, with `in` left as it was. Otherwise `in` is swapped with the slot's previous content: the caller gets
  // back an earlier, already delivered input (or a default one), whose buffers it may reuse instead of allocating.
  bool submit(In& in) { return enqueue(in, true); }
  bool submit(In&& in) { return enqueue(in, true); }
  // Producer. Never blocks, never drops: false (input untouched) when the queue is full or no slot is free;
  // otherwise as submit(). Replay uses it for back-pressure: on false, poll the results and try again.
  bool try_submit(In& in) { return enqueue(in, false); }

  // Consumer. Hands every result whose turn has come to `sink`, in ticket order; returns how many.
  std::size_t poll(const Sink& sink) {
    // Every ticket not yet delivered holds a slot, so no two of them share a place in the ring.
    Slot* s = nullptr;
    while (done_.pop(s)) waiting_[s->ticket % waiting_.size()] = s;
    std::size_t n = 0;
    std::uint64_t next = next_out_.load(std::memory_order_relaxed);
    for (;;) {
      Slot*& at = waiting_[next % waiting_.size()];
      if (at == nullptr || at->ticket != next) break;
      Slot* slot = at;
      at = nullptr;
      next_out_.store(++next, std::memory_order_release);
      deliver(*slot, sink);
      ++n;
    }
    return n;
  }
  // Consumer. Like poll(), but first waits for at least one result; returns 0 only once stopped with nothing
  // outstanding. An output thread loops on it until it returns 0. The producer's own thread may call it only with
  // something outstanding (after a try_submit() that returned false), or it waits for a submission that never comes.
  std::size_t poll_wait(const Sink& sink) {
    for (;;) {
      const std::uint32_t seen = done_epoch_.load(std::memory_order_acquire);
      if (const std::size_t n = poll(sink); n > 0) return n;
      if (outstanding() == 0 && stopped_.load(std::memory_order_acquire)) return 0;
      done_epoch_.wait(seen, std::memory_order_acquire);
    }
  }
  // Tickets issued and not yet delivered.
  [[nodiscard]] std::uint64_t outstanding() const {
    return next_ticket_.load(std::memory_order_acquire) - next_out_.load(std::memory_order_acquire);
  }

  // Owner. Idempotent. Joins the workers; afterwards poll() delivers every outstanding ticket.
  void stop(Drain drain) {
    if (stopping_.exchange(true)) {
      join();
      return;
    }
    drain_ = drain == Drain::Yes;
    stopped_.store(true, std::memory_order_release);
    in_epoch_.fetch_add(1, std::memory_order_acq_rel);
    in_epoch_.notify_all();
    join();
    // Whatever the workers left (Drain::No): reported, not lost.
    Slot* s = nullptr;
    while (input_.pop(s)) finish(*s, Outcome::Discarded);
    // Wakes a consumer idle in poll_wait(), which now returns once it has delivered everything.
    done_epoch_.fetch_add(1, std::memory_order_acq_rel);
    done_epoch_.notify_all();
  }

  // Counters: exact once stopped and polled; a consistent-enough snapshot while running.
  [[nodiscard]] PoolCounters counters() const {
    PoolCounters c;
    c.submitted = next_ticket_.load(std::memory_order_acquire);
    c.refused = refused_.load(std::memory_order_acquire);
    c.processed = processed_.load(std::memory_order_acquire);
    c.failed = failed_.load(std::memory_order_acquire);
    c.dropped = dropped_.load(std::memory_order_acquire);
    c.discarded = discarded_.load(std::memory_order_acquire);
    c.delivered = next_out_.load(std::memory_order_acquire);
    return c;
  }
  [[nodiscard]] const PoolParams& params() const { return params_; }
  // Slots: a bound on the tickets outstanding at any time (submitted and not yet delivered).
  [[nodiscard]] std::size_t slots() const { return slots_.size(); }
  // Producer, while nothing is outstanding: hands the free slots other than the `keep` most recently used to
  // `trim(input, output)` (which frees their buffers, say by assigning a default value). A burst (a sensor back after
  // an outage lets the frames that waited for it go at once) fills more slots than a steady stream reuses; without
  // this their buffers stay with the process for good. Returns how many were trimmed; 0 when anything is
  // outstanding; a slot trimmed and not used since is not counted again. Not while another thread submits.
  template <typename Trim>
  std::size_t trim_idle(std::size_t keep, Trim&& trim) {
    if (outstanding() != 0) return 0;
    std::vector<Slot*>& all = trim_scratch_;  // top of the stack first: the most recently used
    all.clear();
    Slot* s = nullptr;
    while (free_.pop(s)) all.push_back(s);
    std::size_t trimmed = 0;
    for (std::size_t i = keep; i < all.size(); ++i) {
      if (!all[i]->used) continue;  // trimmed before and not used since
      trim(all[i]->input, all[i]->output);
      all[i]->has_output = false;
      all[i]->error = std::string();
      all[i]->used = false;
      ++trimmed;
    }
    for (auto it = all.rbegin(); it != all.rend(); ++it) release(*it);  // back in the same order
    return trimmed;
  }
  // What the system refused of PoolParams::worker, on the first worker that was refused anything; empty when
  // every worker that has started got its settings. Any thread.
  [[nodiscard]] std::string thread_refusal() const {
    if (!has_refusal_.load(std::memory_order_acquire)) return {};  // the daemon asks every tick: no lock then
    const std::lock_guard lock(refusal_mutex_);
    return refusal_;
  }

 private:
  struct Slot {
    std::uint64_t ticket = 0;
    Outcome outcome = Outcome::Processed;
    In input{};
    Out output{};  // kept from ticket to ticket, buffers and all (ProcessInto)
    bool has_output = false;
    bool used = false;  // submitted into since the last trim_idle()
    std::string error;
  };

  static const PoolParams& check(const PoolParams& p) {
    if (p.workers < 1 || p.workers > 64) throw std::invalid_argument("pool: workers must be 1..64");
    if (p.queue_capacity < 1 || p.queue_capacity > 4096) {
      throw std::invalid_argument("pool: queue_capacity must be 1..4096");
    }
    if (p.reorder_slack > 16384) throw std::invalid_argument("pool: reorder_slack must be at most 16384");
    return p;
  }

  bool enqueue(In& in, bool may_drop) {
    if (stopped_.load(std::memory_order_acquire)) return false;
    Slot* s = nullptr;
    if (!free_.pop(s)) {
      if (may_drop) refused_.fetch_add(1, std::memory_order_acq_rel);
      return false;
    }
    if (!may_drop) {
      // Room in the queue is checked before the ticket is issued, so a refused try_submit leaves no gap.
      // Only this thread pushes, so the room seen here cannot be taken by anybody else.
      if (queued_.load(std::memory_order_acquire) >= params_.queue_capacity) {
        release(s);
        return false;
      }
    }
    using std::swap;
    swap(s->input, in);
    s->used = true;
    s->has_output = false;
    s->error.clear();
    s->outcome = Outcome::Processed;
    s->ticket = next_ticket_.load(std::memory_order_relaxed);
    next_ticket_.store(s->ticket + 1, std::memory_order_release);
    queued_.fetch_add(1, std::memory_order_acq_rel);
    while (!input_.bounded_push(s)) {
      if (!may_drop) continue;  // cannot stay full: the room was checked and only workers take from it
      if (params_.drop == DropPolicy::DropNewest) {
        queued_.fetch_sub(1, std::memory_order_acq_rel);
        finish(*s, Outcome::Dropped);
        return true;
      }
      Slot* oldest = nullptr;
      if (input_.pop(oldest)) {  // a worker may have taken it meanwhile: then there is room now
        queued_.fetch_sub(1, std::memory_order_acq_rel);
        finish(*oldest, Outcome::Dropped);
      }
    }
    in_epoch_.fetch_add(1, std::memory_order_acq_rel);
    in_epoch_.notify_one();
    return true;
  }

  void work() {
    if (std::string refused = apply_to_this_thread(params_.worker); !refused.empty()) {
      const std::lock_guard lock(refusal_mutex_);
      if (refusal_.empty()) refusal_ = std::move(refused);
      has_refusal_.store(true, std::memory_order_release);
    }
    for (;;) {
      if (stopped_.load(std::memory_order_acquire) && !drain_) return;
      Slot* s = nullptr;
      const std::uint32_t seen = in_epoch_.load(std::memory_order_acquire);
      if (input_.pop(s)) {
        queued_.fetch_sub(1, std::memory_order_acq_rel);
        run(*s);
        continue;
      }
      if (stopped_.load(std::memory_order_acquire)) return;  // empty and stopping: drained
      in_epoch_.wait(seen, std::memory_order_acquire);
      if (stopped_.load(std::memory_order_acquire) && !drain_) return;
    }
  }

  void run(Slot& s) {
    try {
      process_(s.input, s.output);
      s.has_output = true;
      finish(s, Outcome::Processed);
    } catch (const std::exception& e) {
      s.error = e.what();
      finish(s, Outcome::Failed);
    } catch (...) {
      s.error = "unknown exception";
      finish(s, Outcome::Failed);
    }
  }

  void finish(Slot& s, Outcome o) {
    s.outcome = o;
    switch (o) {
      case Outcome::Processed: processed_.fetch_add(1, std::memory_order_acq_rel); break;
      case Outcome::Failed: failed_.fetch_add(1, std::memory_order_acq_rel); break;
      case Outcome::Dropped: dropped_.fetch_add(1, std::memory_order_acq_rel); break;
      case Outcome::Discarded: discarded_.fetch_add(1, std::memory_order_acq_rel); break;
    }
    // Cannot fail: the done queue has room for every slot.
    while (!done_.bounded_push(&s)) {
    }
    done_epoch_.fetch_add(1, std::memory_order_acq_rel);
    done_epoch_.notify_all();
    if (params_.on_result) params_.on_result();
  }

  void deliver(Slot& s, const Sink& sink) {
    Result r;
    r.ticket = s.ticket;
    r.outcome = s.outcome;
    r.input = &s.input;
    if (s.outcome == Outcome::Processed && s.has_output) r.output = &s.output;
    if (s.outcome == Outcome::Failed) r.error = &s.error;
    try {
      sink(r);
    } catch (...) {
      release(&s);
      throw;
    }
    release(&s);
  }

  void release(Slot* s) {
    // Cannot fail: the free list has room for every slot.
    while (!free_.bounded_push(s)) {
    }
  }

  void join() {
    for (std::thread& t : workers_) {
      if (t.joinable()) t.join();
    }
  }

  using PtrQueue = boost::lockfree::queue<Slot*, boost::lockfree::fixed_sized<true>>;
  // Free slots last in, first out: the few slots a steady stream needs are reused again and again, so their buffers
  // (inputs handed back to the producer, outputs written over) are warm after a few frames, not after every slot.
  using PtrStack = boost::lockfree::stack<Slot*, boost::lockfree::fixed_sized<true>>;

  PoolParams params_;
  ProcessInto process_;
  std::vector<Slot> slots_;
  std::vector<Slot*> trim_scratch_;  // trim_idle(): reserved for every slot, so it does not allocate
  PtrStack free_;
  PtrQueue input_;
  PtrQueue done_;
  std::atomic<std::size_t> queued_{0};
  std::atomic<std::uint64_t> next_ticket_{0};
  std::atomic<std::uint64_t> refused_{0}, processed_{0}, failed_{0}, dropped_{0}, discarded_{0};
  std::atomic<std::uint32_t> in_epoch_{0};
  std::atomic<std::uint32_t> done_epoch_{0};
  std::atomic<bool> stopped_{false};
  std::atomic<bool> stopping_{false};
  bool drain_ = true;  // written before stopped_ is released, read after it is acquired
  std::vector<std::thread> workers_;
  mutable std::mutex refusal_mutex_;
  std::string refusal_;
  std::atomic<bool> has_refusal_{false};  // refusal_ is set
  // Consumer only.
  std::vector<Slot*> waiting_;              // finished, by ticket modulo its size (the slots'), until their turn
  std::atomic<std::uint64_t> next_out_{0};  // written by the consumer only; atomic for counters()
};

}  // namespace fieldguard::sync
