#pragma once
// Subcommands register themselves: a file in app/commands/ defines a static CommandRegistrar
// whose setup function adds its CLI11 subcommand and callback. Keeps main.cpp free of a list
// that every new command would have to edit.
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace mirage::app {

struct CommandSpec {
    std::string name;
    std::function<void(CLI::App& parent)> setup;
};

std::vector<CommandSpec>& commandRegistry();

struct CommandRegistrar {
    CommandRegistrar(std::string name, std::function<void(CLI::App&)> setup) {
        commandRegistry().push_back({std::move(name), std::move(setup)});
    }
};

// Exit code a command sets for main() to return (0 = success).
int& commandExitCode();

// The process's arguments as given (argv), for records of how an output was made (shard
// manifests name the command that reruns them).
std::vector<std::string>& commandLine();

}  // namespace mirage::app
