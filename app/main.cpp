// mirage: one binary, subcommands (docs/cli.md). Errors from bad input are reported as
// "error: <file>: <problem>" with a non-zero exit; internal check failures say they are bugs.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>

#include <CLI/CLI.hpp>

#include "app/Command.h"
#include "core/Error.h"
#include "core/Log.h"

namespace {

// `mirage --list-options`: every subcommand's options as CLI11 holds them, one per line,
// tab-separated: command, name, kind (flag, positional, option), type with its validators'
// descriptions ("FLOAT:in (0, 179)"), values per use, validator names. Hidden from the help;
// the CLI conformance test (tests/app/CliConformance_test.cpp) walks this list.
void listOptions(CLI::App& cli) {
    for (CLI::App* sub : cli.get_subcommands({})) {
        for (const CLI::Option* opt : sub->get_options()) {
            if (opt->get_name() == "--help" || opt->get_name() == "-h,--help") continue;
            const bool flag = opt->get_items_expected_max() == 0;
            std::string validators;
            for (int i = 0;; ++i) {
                try {
                    validators += (i ? "," : "") +
                                  const_cast<CLI::Option*>(opt)->get_validator(i)->get_name();
                } catch (const CLI::OptionNotFound&) {
                    break;
                }
            }
            std::printf("%s\t%s\t%s\t%s\t%d\t%s\n", sub->get_name().c_str(),
                        opt->get_name(false, true).c_str(),
                        flag                   ? "flag"
                        : opt->nonpositional() ? "option"
                                               : "positional",
                        opt->get_type_name().c_str(), opt->get_items_expected_max(),
                        validators.c_str());
        }
    }
}

}  // namespace

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
    if (argc == 2 && std::string(argv[1]) == "--list-options") {
        listOptions(cli);
        return 0;
    }

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
