#pragma once
// CSV fields as mirage writes and reads them (RFC 4180): fields separated by commas, a field
// holding a comma, quote or newline is wrapped in double quotes with quotes doubled inside.
#include <string>
#include <string_view>
#include <vector>

namespace mirage {

// Splits one CSV line into fields, undoing the quoting. An unterminated quote ends the field at
// the end of the line (lenient: a damaged row parses instead of throwing; callers validate).
std::vector<std::string> splitCsvLine(std::string_view line);
// Quotes a field when it needs it.
std::string csvField(std::string_view value);

}  // namespace mirage
