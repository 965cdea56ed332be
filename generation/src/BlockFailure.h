#pragma once
// Which exceptions a style may turn into one block's failure or fallback.
#include <new>

#include "parcelscope/core/Error.h"

namespace parcelscope::generation::detail {

/// Call inside a catch block: rethrows what no block may absorb (memory
/// exhausted, a stop asked for, a usage error), so that it stops the run;
/// returns for anything else (a geometric failure, CGAL's failed
/// preconditions), which the caller records as the block's failure.
inline void rethrowUnlessBlockFailure() {
  try {
    throw;
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const Error& e) {
    if (e.kind() == Error::Kind::Cancelled || e.kind() == Error::Kind::Usage) throw;
  } catch (...) {
  }
}

}  // namespace parcelscope::generation::detail
