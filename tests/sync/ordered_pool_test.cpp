// The lock-free hand-off and the worker pool: order, drops, failures and shutdown. Threaded: run under
// ThreadSanitizer in CI (tools/test).

#include "fieldguard/sync/ordered_pool.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace fieldguard::sync {
namespace {

struct Item {
  std::uint64_t seq = 0;
  std::vector<std::uint32_t> payload;
};

// Deterministic work whose duration varies with the item, so workers finish out of order.
std::uint64_t digest(const Item& it) {
  std::uint64_t h = 1469598103934665603ULL ^ it.seq;
  const int rounds = 200 + static_cast<int>((it.seq * 7919) % 3000);
  for (int r = 0; r < rounds; ++r) {
    for (std::uint32_t v : it.payload) h = (h ^ v) * 1099511628211ULL;
  }
  return h;
}

Item make_item(std::uint64_t seq) {
  Item it;
  it.seq = seq;
  for (std::uint32_t i = 0; i < 16; ++i) it.payload.push_back(static_cast<std::uint32_t>(seq * 31 + i));
  return it;
}

struct Delivered {
  std::uint64_t ticket = 0;
  std::uint64_t seq = 0;
  Outcome outcome = Outcome::Processed;
  std::uint64_t value = 0;
  std::string error;
};

std::vector<Delivered> run_all(std::size_t workers, std::uint64_t n) {
  PoolParams p;
  p.workers = workers;
  p.queue_capacity = 16;
  OrderedPool<Item, std::uint64_t> pool(p, [](Item& it) { return digest(it); });
  std::vector<Delivered> out;
  const auto sink = [&](const auto& r) {
    out.push_back({r.ticket, r.input->seq, r.outcome, r.output != nullptr ? *r.output : 0, ""});
  };
  for (std::uint64_t i = 0; i < n; ++i) {
    Item it = make_item(i);
    while (!pool.try_submit(it)) pool.poll_wait(sink);  // replay's back-pressure: never drops
    // What comes back is a slot's earlier input, already delivered, or a fresh one: never the one just sent.
    EXPECT_TRUE(it.payload.empty() || (it.seq < i && it.seq < out.size())) << i;
  }
  pool.stop(Drain::Yes);
  pool.poll(sink);
  const PoolCounters c = pool.counters();
  EXPECT_EQ(c.submitted, n);
  EXPECT_EQ(c.processed, n);
  EXPECT_EQ(c.dropped + c.refused + c.failed + c.discarded, 0U);
  return out;
}

TEST(OrderedPool, OneAndFourWorkersGiveIdenticalOrderedOutput) {
  constexpr std::uint64_t kN = 3000;
  const auto one = run_all(1, kN);
  const auto four = run_all(4, kN);
  ASSERT_EQ(one.size(), kN);
  ASSERT_EQ(four.size(), kN);
  for (std::uint64_t i = 0; i < kN; ++i) {
    ASSERT_EQ(one[i].ticket, i);
    ASSERT_EQ(one[i].seq, i);
    ASSERT_EQ(four[i].seq, i);
    ASSERT_EQ(four[i].outcome, Outcome::Processed);
    ASSERT_EQ(one[i].value, four[i].value) << i;
    ASSERT_EQ(one[i].value, digest(make_item(i))) << i;
  }
}

// A gate that holds the single worker inside its first job, so the queue fills deterministically.
struct Gate {
  std::atomic<bool> open{false};
  std::atomic<int> entered{0};
  void pass() {
    entered.fetch_add(1);
    while (!open.load()) std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  void wait_entered(int n) const {
    while (entered.load() < n) std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
};

struct FullQueueResult {
  PoolCounters counters;
  std::vector<Delivered> delivered;
};

// One worker blocked on item 0; 100 submitted; capacity 4, reorder slack 16: 1 + 4 + 16 + 1 = 22 slots.
FullQueueResult full_queue(DropPolicy policy) {
  Gate gate;
  PoolParams p;
  p.workers = 1;
  p.queue_capacity = 4;
  p.reorder_slack = 16;
  p.drop = policy;
  OrderedPool<Item, std::uint64_t> pool(p, [&](Item& it) {
    if (it.seq == 0) gate.pass();
    return it.seq * 10;
  });
  FullQueueResult r;
  const auto sink = [&](const auto& res) {
    r.delivered.push_back({res.ticket, res.input->seq, res.outcome, res.output != nullptr ? *res.output : 0, ""});
  };
  pool.submit(make_item(0));
  gate.wait_entered(1);
  for (std::uint64_t i = 1; i < 100; ++i) pool.submit(make_item(i));  // the io thread: never waits
  pool.poll(sink);                                                    // nothing can be delivered while item 0 is held
  EXPECT_TRUE(r.delivered.empty());
  gate.open.store(true);
  pool.stop(Drain::Yes);
  pool.poll(sink);
  r.counters = pool.counters();
  return r;
}

TEST(OrderedPool, FullQueueDropsNewestAndCountsExactly) {
  const auto r = full_queue(DropPolicy::DropNewest);
  const PoolCounters& c = r.counters;
  // Slots: 1 in the worker + 4 queued + 17 dropped waiting for their turn; the other 78 found no slot.
  EXPECT_EQ(c.processed, 5U);
  EXPECT_EQ(c.dropped, 17U);
  EXPECT_EQ(c.refused, 78U);
  EXPECT_EQ(c.failed + c.discarded, 0U);
  EXPECT_EQ(c.submitted, c.processed + c.dropped);
  EXPECT_EQ(c.submitted + c.refused, 100U);
  ASSERT_EQ(r.delivered.size(), 22U);
  for (std::size_t i = 0; i < r.delivered.size(); ++i) {
    EXPECT_EQ(r.delivered[i].ticket, i);
    EXPECT_EQ(r.delivered[i].seq, i);
    EXPECT_EQ(r.delivered[i].outcome, i < 5 ? Outcome::Processed : Outcome::Dropped) << i;
  }
}

TEST(OrderedPool, FullQueueDropsOldestAndCountsExactly) {
  const auto r = full_queue(DropPolicy::DropOldest);
  const PoolCounters& c = r.counters;
  EXPECT_EQ(c.processed, 5U);
  EXPECT_EQ(c.dropped, 17U);
  EXPECT_EQ(c.refused, 78U);
  EXPECT_EQ(c.submitted, c.processed + c.dropped);
  ASSERT_EQ(r.delivered.size(), 22U);
  // Item 0 was in the worker; of 1..21 the oldest went, the newest four were processed.
  for (std::size_t i = 0; i < r.delivered.size(); ++i) {
    const bool kept = i == 0 || i >= 18;
    EXPECT_EQ(r.delivered[i].outcome, kept ? Outcome::Processed : Outcome::Dropped) << i;
    if (kept) {
      EXPECT_EQ(r.delivered[i].value, i * 10);
    }
  }
}

// A slow worker fed faster than it can go, with the consumer polling as it runs: drops happen, and every
// submission is accounted for, in order.
TEST(OrderedPool, SlowWorkerUnderLoadAccountsForEverySubmission) {
  PoolParams p;
  p.workers = 2;
  p.queue_capacity = 8;
  p.drop = DropPolicy::DropOldest;
  OrderedPool<Item, std::uint64_t> pool(p, [](Item& it) {
    std::this_thread::sleep_for(std::chrono::microseconds(300));
    return it.seq;
  });
  std::uint64_t next = 0;
  std::uint64_t processed = 0;
  std::uint64_t dropped = 0;
  bool ordered = true;
  const auto sink = [&](const auto& r) {
    ordered = ordered && r.ticket == next;
    ++next;
    if (r.outcome == Outcome::Processed) ++processed;
    if (r.outcome == Outcome::Dropped) ++dropped;
  };
  constexpr std::uint64_t kSent = 4000;
  for (std::uint64_t i = 0; i < kSent; ++i) {
    pool.submit(make_item(i));
    if (i % 64 == 0) pool.poll(sink);
  }
  pool.stop(Drain::Yes);
  pool.poll(sink);
  const PoolCounters c = pool.counters();
  EXPECT_TRUE(ordered);
  EXPECT_GT(c.dropped, 0U);
  EXPECT_EQ(c.processed, processed);
  EXPECT_EQ(c.dropped, dropped);
  EXPECT_EQ(c.submitted, c.processed + c.dropped);
  EXPECT_EQ(c.submitted + c.refused, kSent);
  EXPECT_EQ(c.delivered, c.submitted);
  std::printf("slow worker: sent %llu, processed %llu, dropped %llu, refused %llu\n",
              static_cast<unsigned long long>(kSent), static_cast<unsigned long long>(c.processed),
              static_cast<unsigned long long>(c.dropped), static_cast<unsigned long long>(c.refused));
}

TEST(OrderedPool, ThrowingJobIsReportedInItsPlace) {
  PoolParams p;
  p.workers = 3;
  OrderedPool<Item, std::uint64_t> pool(p, [](Item& it) -> std::uint64_t {
    if (it.seq % 7 == 3) throw std::runtime_error("bad frame " + std::to_string(it.seq));
    if (it.seq % 11 == 5) throw 42;  // not even an exception type
    return it.seq;
  });
  std::vector<Delivered> out;
  const auto sink = [&](const auto& r) {
    out.push_back(
        {r.ticket, r.input->seq, r.outcome, r.output != nullptr ? *r.output : 0, r.error != nullptr ? *r.error : ""});
  };
  for (std::uint64_t i = 0; i < 200; ++i) {
    Item it = make_item(i);
    while (!pool.try_submit(it)) pool.poll_wait(sink);
  }
  pool.stop(Drain::Yes);
  pool.poll(sink);
  ASSERT_EQ(out.size(), 200U);
  std::uint64_t failed = 0;
  for (std::uint64_t i = 0; i < 200; ++i) {
    EXPECT_EQ(out[i].seq, i);
    if (i % 7 == 3) {
      EXPECT_EQ(out[i].outcome, Outcome::Failed);
      EXPECT_EQ(out[i].error, "bad frame " + std::to_string(i));
      ++failed;
    } else if (i % 11 == 5) {
      EXPECT_EQ(out[i].outcome, Outcome::Failed);
      EXPECT_EQ(out[i].error, "unknown exception");
      ++failed;
    } else {
      EXPECT_EQ(out[i].outcome, Outcome::Processed);
      EXPECT_EQ(out[i].value, i);
    }
  }
  EXPECT_EQ(pool.counters().failed, failed);
  EXPECT_EQ(pool.counters().processed + failed, 200U);
}

TEST(OrderedPool, StopWithoutDrainReportsWhatItDiscarded) {
  Gate gate;
  PoolParams p;
  p.workers = 1;
  p.queue_capacity = 4;
  OrderedPool<Item, std::uint64_t> pool(p, [&](Item& it) {
    if (it.seq == 0) gate.pass();
    return it.seq;
  });
  pool.submit(make_item(0));
  gate.wait_entered(1);
  for (std::uint64_t i = 1; i <= 4; ++i) pool.submit(make_item(i));
  std::thread opener([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    gate.open.store(true);
  });
  pool.stop(Drain::No);
  opener.join();
  std::vector<Delivered> out;
  pool.poll([&](const auto& r) { out.push_back({r.ticket, r.input->seq, r.outcome, 0, ""}); });
  ASSERT_EQ(out.size(), 5U);
  EXPECT_EQ(out[0].outcome, Outcome::Processed);
  for (std::size_t i = 1; i < 5; ++i) {
    EXPECT_EQ(out[i].outcome, Outcome::Discarded);
    EXPECT_EQ(out[i].seq, i);  // the consumer learns which inputs were lost
  }
  const PoolCounters c = pool.counters();
  EXPECT_EQ(c.discarded, 4U);
  EXPECT_EQ(c.processed, 1U);
  EXPECT_EQ(pool.outstanding(), 0U);
  EXPECT_FALSE(pool.submit(make_item(9)));  // stopped: refused
  pool.stop(Drain::No);                     // idempotent
}

// The live layout: the io thread submits, an output thread waits for results, idle between frames, and
// leaves once the pool is stopped and everything is delivered.
TEST(OrderedPool, OutputThreadWaitsIdleAndLeavesAfterStop) {
  PoolParams p;
  p.workers = 3;
  p.queue_capacity = 8;
  OrderedPool<Item, std::uint64_t> pool(p, [](Item& it) { return digest(it); });
  std::vector<std::uint64_t> seqs;
  bool outputs_right = true;
  std::thread output([&] {
    const auto sink = [&](const auto& r) {
      seqs.push_back(r.input->seq);
      outputs_right = outputs_right && (r.outcome != Outcome::Processed || *r.output == digest(*r.input));
    };
    while (pool.poll_wait(sink) > 0) {
    }
  });
  for (std::uint64_t i = 0; i < 200; ++i) {
    pool.submit(make_item(i));
    if (i % 50 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));  // the consumer goes idle
  }
  pool.stop(Drain::Yes);
  output.join();
  const PoolCounters c = pool.counters();
  EXPECT_EQ(c.submitted + c.refused, 200U);
  EXPECT_EQ(c.delivered, c.submitted);
  EXPECT_EQ(c.processed + c.dropped, c.submitted);
  ASSERT_EQ(seqs.size(), c.submitted);
  for (std::size_t i = 1; i < seqs.size(); ++i) EXPECT_LT(seqs[i - 1], seqs[i]);
  EXPECT_TRUE(outputs_right);
}

TEST(OrderedPool, DestructorStopsIdleAndBusyPools) {
  for (int busy = 0; busy < 2; ++busy) {
    PoolParams p;
    p.workers = 4;
    OrderedPool<Item, std::uint64_t> pool(p, [](Item& it) { return digest(it); });
    if (busy != 0) {
      for (std::uint64_t i = 0; i < 50; ++i) pool.submit(make_item(i));
    }
  }
  SUCCEED();  // reaching here means every worker was woken and joined
}

// The daemon's hand-off: a consumer that only polls when told (PoolParams::on_result, called on the worker that
// finished) still gets every result, in order, and is told at least once after the last one. Runs under TSan.
TEST(OrderedPool, OnResultWakesAConsumerThatPollsOnlyWhenTold) {
  std::mutex m;
  std::condition_variable cv;
  std::uint64_t told = 0;
  PoolParams p;
  p.workers = 4;
  p.queue_capacity = 64;
  p.on_result = [&] {
    const std::lock_guard lock(m);
    ++told;
    cv.notify_one();
  };
  OrderedPool<Item, std::uint64_t> pool(p, [](Item& it) { return digest(it); });
  constexpr std::uint64_t kItems = 200;
  constexpr std::uint64_t kBatch = 50;  // fits the pool's slots: nothing is refused or dropped
  std::vector<std::uint64_t> seqs;
  std::uint64_t seen = 0;
  for (std::uint64_t i = 0; i < kItems;) {
    for (const std::uint64_t end = i + kBatch; i < end; ++i) ASSERT_TRUE(pool.submit(make_item(i)));
    while (seqs.size() < i) {
      {
        std::unique_lock lock(m);
        cv.wait(lock, [&] { return told > seen; });  // no timeout: a missing wake-up hangs and fails the test
        seen = told;
      }
      pool.poll([&](const auto& r) {
        ASSERT_EQ(r.outcome, Outcome::Processed);
        seqs.push_back(r.input->seq);
      });
    }
  }
  for (std::uint64_t i = 0; i < kItems; ++i) EXPECT_EQ(seqs[i], i);
  EXPECT_GE(seen, 1U);
  pool.stop(Drain::Yes);
}

// ProcessInto writes each result over its slot's earlier one, and a steady producer, one frame at a time, keeps using
// the same few slots (the free list is last in, first out): after the first frames no buffer is new, on either side.
TEST(OrderedPool, ProcessIntoReusesTheBuffersOfAFewSlots) {
  PoolParams p;
  p.workers = 2;
  p.queue_capacity = 8;
  OrderedPool<Item, std::vector<std::uint64_t>> pool(p, [](Item& it, std::vector<std::uint64_t>& out) {
    out.assign(64, digest(it));  // the same size every time: the earlier result's room suffices
  });
  std::set<const void*> outputs;
  std::set<const void*> inputs;
  std::uint64_t checked = 0;
  const auto sink = [&](const auto& r) {
    ASSERT_EQ(r.outcome, Outcome::Processed);
    ASSERT_NE(r.output, nullptr);
    EXPECT_EQ(r.output->front(), digest(*r.input)) << "the result is this ticket's, not an earlier one's";
    if (r.ticket >= 10) outputs.insert(r.output->data());
    ++checked;
  };
  Item in;
  for (std::uint64_t seq = 0; seq < 200; ++seq) {
    in.seq = seq;
    in.payload.resize(16);  // a handed-back input keeps its room
    for (std::uint32_t i = 0; i < 16; ++i) in.payload[i] = static_cast<std::uint32_t>(seq * 31 + i);
    if (seq >= 10) inputs.insert(in.payload.data());
    ASSERT_TRUE(pool.submit(in));
    while (pool.outstanding() > 0) pool.poll_wait(sink);
  }
  pool.stop(Drain::Yes);
  pool.poll(sink);
  EXPECT_EQ(checked, 200U);
  // One frame at a time: the slot just released is the next one taken.
  EXPECT_LE(outputs.size(), 2U) << "results written into new buffers";
  EXPECT_LE(inputs.size(), 2U) << "inputs handed back from other slots than the last";
}

// A burst fills many slots; once idle, trim_idle() empties all but the most recently used, and a steady stream after
// it goes on in the kept slot's buffers (no new one). Nothing is trimmed while a ticket is outstanding.
TEST(OrderedPool, TrimIdleEmptiesTheSlotsABurstFilled) {
  PoolParams p;
  p.workers = 2;
  p.queue_capacity = 8;
  OrderedPool<Item, std::vector<std::uint64_t>> pool(
      p, [](Item& it, std::vector<std::uint64_t>& out) { out.assign(4096, digest(it)); });
  std::vector<const void*> last_outputs;
  const auto sink = [&](const auto& r) {
    ASSERT_EQ(r.outcome, Outcome::Processed);
    last_outputs.push_back(r.output->data());
  };
  const auto trim = [](Item& in, std::vector<std::uint64_t>& out) {
    in = Item{};
    out = std::vector<std::uint64_t>{};
  };
  Item in;
  for (std::uint64_t seq = 0; seq < 8; ++seq) {  // the burst: 8 at once
    in.seq = seq;
    in.payload.assign(1024, static_cast<std::uint32_t>(seq));
    ASSERT_TRUE(pool.submit(in));
  }
  EXPECT_EQ(pool.trim_idle(1, trim), 0U) << "trimmed with tickets outstanding";
  while (pool.outstanding() > 0) pool.poll_wait(sink);
  ASSERT_EQ(last_outputs.size(), 8U);
  const std::size_t trimmed = pool.trim_idle(1, trim);
  EXPECT_GE(trimmed, 6U);  // the burst used 7 or 8 slots (a worker may have finished one before the last submit)
  EXPECT_LE(trimmed, 7U);
  EXPECT_EQ(pool.trim_idle(1, trim), 0U) << "slots trimmed again without being used";
  // Steady again, one at a time: every result in the kept slot's buffer, the last one of the burst.
  const void* kept = last_outputs.back();
  last_outputs.clear();
  for (std::uint64_t seq = 8; seq < 20; ++seq) {
    in.seq = seq;
    ASSERT_TRUE(pool.submit(in));
    while (pool.outstanding() > 0) pool.poll_wait(sink);
  }
  for (const void* o : last_outputs) EXPECT_EQ(o, kept);
  pool.stop(Drain::Yes);
}

TEST(OrderedPool, RejectsBadParameters) {
  const auto f = [](Item& it) { return it.seq; };
  PoolParams p;
  p.workers = 0;
  EXPECT_THROW((OrderedPool<Item, std::uint64_t>(p, f)), std::invalid_argument);
  p.workers = 1;
  p.queue_capacity = 0;
  EXPECT_THROW((OrderedPool<Item, std::uint64_t>(p, f)), std::invalid_argument);
}

}  // namespace
}  // namespace fieldguard::sync
