#pragma once
// Creation times written into outputs (session.json, calibration files, shard manifests).
#include <string>

namespace mirage {

// The current time, UTC, ISO 8601 to the second ("2026-12-01T21:37:49Z") — or, when the
// environment variable SOURCE_DATE_EPOCH holds whole seconds since 1970 (the reproducible-builds
// convention), that time: then two runs with the same inputs write identical files, which is how
// a split run is checked against the whole one (docs/scale.md). Throws mirage::Error if the
// variable is set but not a whole number.
std::string utcTimestamp();

}  // namespace mirage
