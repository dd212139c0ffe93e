// mirage: one binary, subcommands (docs/cli.md). Errors from bad input are reported as
// "error: <file>: <problem>" with a non-zero exit; internal check failures say they are bugs.
#include <algorithm>
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>

#include "app/Command.h"
#include "core/Error.h"
#include "core/Log.h"

int main(int argc, char** argv) {
    using namespace mirage;
    app::commandLine().assign(argv, argv + argc);
    CLI::App cli{
        "mirage: virtual glass, mirrors and translucent objects composited into real "
        "camera footage"};
    cli.set_version_flag("--version", std::string("mirage ") + MIRAGE_VERSION);
    std::string logLevel = "info";
    cli.add_option("--log-level", logLevel, "trace, debug, info, warn, error, off")
        ->capture_default_str();
    cli.require_subcommand(1);
    // Options of `mirage` itself (--log-level) are accepted after the subcommand as well.
    cli.fallthrough();

    auto& registry = app::commandRegistry();
    std::sort(registry.begin(), registry.end(),
              [](const auto& a, const auto& b) { return a.name < b.name; });
    for (auto& spec : registry) spec.setup(cli);
    cli.parse_complete_callback([&] { setLogLevel(logLevel); });

    try {
        cli.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help and --version exit 0; every argument error exits 1 (docs/conventions.md), not
        // CLI11's own codes (104-114).
        return cli.exit(e) == 0 ? 0 : 1;
    } catch (const Error& e) {
        spdlog::error("{}", e.what());
        return 1;
    } catch (const std::logic_error& e) {
        spdlog::critical("{}", e.what());
        return 3;
    } catch (const std::exception& e) {
        spdlog::error("{}", e.what());
        return 1;
    }
    return app::commandExitCode();
}
