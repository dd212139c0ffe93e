#include "app/Command.h"

namespace mirage::app {
std::vector<CommandSpec>& commandRegistry() {
    static std::vector<CommandSpec> r;
    return r;
}
int& commandExitCode() {
    static int code = 0;
    return code;
}
std::vector<std::string>& commandLine() {
    static std::vector<std::string> args;
    return args;
}
}  // namespace mirage::app
