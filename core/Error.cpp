#include "core/Error.h"

#include <sstream>

namespace mirage {

// An invariant failed: report it as a bug with its location. Thrown (not aborted) so that a
// library user can recover and so tests can assert on it.
void checkFailed(const char* expr, const std::string& msg, std::source_location where) {
    std::ostringstream s;
    s << "internal check failed (a bug in mirage): " << expr << " at " << where.file_name() << ":"
      << where.line() << (msg.empty() ? "" : ": ") << msg;
    throw std::logic_error(s.str());
}

}  // namespace mirage
