// A loop over elements split between a few threads.
#pragma once

#include <algorithm>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace textile::assembly
{

/// Calls body(begin, end, thread) on num_threads contiguous parts of
/// [0, n), thread 0 on the calling thread. The split depends on n and
/// num_threads only, so results are reproducible. If bodies throw, the
/// exception of the lowest part is rethrown after all threads finished.
template <typename Body>
void parallel_for(std::size_t n, int num_threads, Body&& body)
{
  const std::size_t parts = std::max<std::size_t>(1, std::min<std::size_t>(num_threads, n));
  if (parts == 1)
  {
    body(std::size_t(0), n, 0);
    return;
  }
  std::vector<std::exception_ptr> errors(parts);
  auto run = [&](std::size_t t)
  {
    try
    {
      body(n * t / parts, n * (t + 1) / parts, static_cast<int>(t));
    }
    catch (...)
    {
      errors[t] = std::current_exception();
    }
  };
  {
    std::vector<std::jthread> threads;
    for (std::size_t t = 1; t < parts; ++t)
      threads.emplace_back(run, t);
    run(0);
  } // joined
  for (auto& e : errors)
    if (e)
      std::rethrow_exception(e);
}

} // namespace textile::assembly
