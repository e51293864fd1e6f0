// Items computed on a few threads and consumed in order by the caller.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace textile::assembly
{

/// Calls produce(c, slot) for every item c in [0, n) on num_threads threads
/// (the calling thread included) and consume(c, slot) on the calling thread
/// in the order c = 0, 1, ..., n - 1, as soon as item c is produced: the
/// caller's serial work overlaps the others' production. Item c lives in
/// storage slot c % slots, so at most `slots` items are ahead of
/// consumption (slots >= 1). The first exception stops the pipeline and is
/// rethrown once every thread has finished.
template <typename Produce, typename Consume>
void ordered_pipeline(std::size_t n, int num_threads, std::size_t slots, Produce&& produce,
                      Consume&& consume)
{
  if (num_threads <= 1 or n <= 1)
  {
    for (std::size_t c = 0; c < n; ++c)
    {
      produce(c, c % slots);
      consume(c, c % slots);
    }
    return;
  }
  std::vector<std::atomic<bool>> ready(n); // value-initialized: false
  std::atomic<std::size_t> next{0}, consumed{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto fail = [&]
  {
    std::lock_guard lock(error_mutex);
    if (!error)
      error = std::current_exception();
    failed = true;
  };
  // produce item c once its slot is free (item c - slots consumed)
  auto produce_when_free = [&](std::size_t c)
  {
    while (consumed.load(std::memory_order_acquire) + slots <= c)
    {
      if (failed)
        return;
      std::this_thread::yield();
    }
    produce(c, c % slots);
    ready[c].store(true, std::memory_order_release);
  };
  auto worker = [&]
  {
    try
    {
      for (std::size_t c = next++; c < n and !failed; c = next++)
        produce_when_free(c);
    }
    catch (...)
    {
      fail();
    }
  };
  {
    std::vector<std::jthread> threads;
    for (int t = 1; t < std::min<std::size_t>(num_threads, n); ++t)
      threads.emplace_back(worker);
    try
    {
      while (consumed < n and !failed)
      {
        const std::size_t c = consumed.load();
        if (ready[c].load(std::memory_order_acquire))
        {
          consume(c, c % slots);
          consumed.store(c + 1, std::memory_order_release);
          continue;
        }
        // not ready: produce one item meanwhile, or wait for item c
        const std::size_t mine = next++;
        if (mine >= n)
        {
          std::this_thread::yield();
          continue;
        }
        // its slot frees only when this thread consumes the items before it
        while (consumed + slots <= mine and !failed)
        {
          const std::size_t d = consumed.load();
          if (ready[d].load(std::memory_order_acquire))
          {
            consume(d, d % slots);
            consumed.store(d + 1, std::memory_order_release);
          }
          else
            std::this_thread::yield();
        }
        if (!failed)
          produce_when_free(mine);
      }
    }
    catch (...)
    {
      fail();
    }
  } // joined
  if (error)
    std::rethrow_exception(error);
}

} // namespace textile::assembly
