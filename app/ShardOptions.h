#pragma once
// Validators of --shard I/N and of item ranges (--frames A:B, --rows A:B), so that a malformed
// or empty value ("--shard ''") is refused while the command line is parsed, with the message of
// core/Shards.h naming the option, instead of being taken as "no shard".
#include <string>

#include <CLI/CLI.hpp>

#include "core/Error.h"
#include "core/Shards.h"

namespace mirage::app {

inline CLI::Validator shardSpecCheck() {
    return CLI::Validator(
        [](std::string& value) -> std::string {
            try {
                parseShardSpec(value);
            } catch (const Error& e) {
                return e.what();
            }
            return {};
        },
        "I/N");
}

// `option` names the option in the message ("--rows").
inline CLI::Validator itemRangeCheck(const std::string& option) {
    return CLI::Validator(
        [option](std::string& value) -> std::string {
            try {
                parseItemRange(value, option);
            } catch (const Error& e) {
                return e.what();
            }
            return {};
        },
        "A:B");
}

}  // namespace mirage::app
