#pragma once
// A call on a given thread count: the library's functions take theirs from the calling thread's
// ExecutionScope (focal/core/execution.h).

#include <utility>

#include "focal/core/execution.h"

namespace focal::test {

/// call() inside an ExecutionScope of `threads` threads.
template <class Call>
decltype(auto) on_threads(int threads, Call&& call) {
  const ExecutionScope scope({.threads = threads});
  return std::forward<Call>(call)();
}

}  // namespace focal::test
