// `mirage slurm --shards N [resources] -- synth|render|bench|replay ARGS...`: runs a long command
// on a Slurm cluster as a job array, one shard per task (`--shard $SLURM_ARRAY_TASK_ID/N`), and a
// merge job that starts when every task succeeded (`--dependency=afterok`). The scheduler does
// queuing, retries and placement; mirage only writes the two batch scripts into OUT.slurm/,
// submits them with sbatch and says how to follow them (docs/scale.md). The output folder must be
// on storage every node sees.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <regex>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "app/Command.h"
#include "app/NumberChecks.h"
#include "core/Error.h"
#include "core/Log.h"
#include "core/OutputFile.h"
#include "core/Shards.h"

namespace mirage::app {
namespace {

namespace fs = std::filesystem;

struct SlurmArgs {
    int shards = 0;
    int cpus = 2;
    int memoryMb = 0;  // 0 = estimated
    std::string timeLimit = "04:00:00";
    std::string partition, account, sbatch = "sbatch", mirage;
    bool dryRun = false;
    std::vector<std::string> command;  // synth|render|bench and its arguments
};

// sbatch's --time formats (man sbatch): minutes, minutes:seconds, hours:minutes:seconds,
// days-hours, days-hours:minutes, days-hours:minutes:seconds, with at least one minute or day;
// checked here so that a typo fails now, not when the cluster reads the script.
CLI::Validator slurmTime() {
    return CLI::Validator(
        [](std::string& v) -> std::string {
            static const std::regex format(
                R"((\d{1,7})|(\d{1,7}):(\d{1,2})|(\d{1,5}):(\d{1,2}):(\d{1,2})|)"
                R"((\d{1,5})-(\d{1,2})|(\d{1,5})-(\d{1,2}):(\d{1,2})|)"
                R"((\d{1,5})-(\d{1,2}):(\d{1,2}):(\d{1,2}))");
            std::smatch m;
            if (!std::regex_match(v, m, format) || v.find_first_not_of("0:-") == std::string::npos)
                return "'" + v +
                       "' is not a Slurm time limit: use M, M:S, H:M:S, D-H, D-H:M or D-H:M:S "
                       "(e.g. 04:00:00), more than zero";
            return {};
        },
        "TIME");
}

// Partition and account names go into the batch script's #SBATCH lines: plain names only.
CLI::Validator slurmName() {
    return CLI::Validator(
        [](std::string& v) -> std::string {
            if (v.empty() ||
                v.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                    "0123456789_.,-") != std::string::npos)
                return "'" + v + "' is not a Slurm name (letters, digits, _ . , - only)";
            return {};
        },
        "NAME");
}

std::string quote(const std::string& s) {
    if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                          "0123456789_-./=:,+@%") == std::string::npos)
        return s;
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

// The value of option `name` (or its short form) in `args`, or "".
std::string optionValue(const std::vector<std::string>& args, const std::string& name,
                        const std::string& shortName = "") {
    for (size_t i = 0; i < args.size(); ++i) {
        if ((args[i] == name || (!shortName.empty() && args[i] == shortName)) &&
            i + 1 < args.size())
            return args[i + 1];
        if (args[i].rfind(name + "=", 0) == 0) return args[i].substr(name.size() + 1);
    }
    return "";
}

int intOption(const std::vector<std::string>& args, const std::string& name, int fallback) {
    const std::string v = optionValue(args, name);
    try {
        return v.empty() ? fallback : std::stoi(v);
    } catch (const std::exception&) {
        return fallback;  // the command itself reports the bad value
    }
}

// Memory per task (MB): the reference renderer holds per pixel a double accumulator, hit counts
// and a few float images (~200 B), the photon map about as much again at its automatic size
// (pixels / 2 photons per pass), the scene about 8x its file size once in Embree's BVH; plus
// 512 MB for the process, OpenCV and (bench) llvmpipe. Rounded up to 256 MB. An estimate: pass
// --mem to set it.
int estimateMemoryMb(const std::vector<std::string>& args) {
    const std::string cmd = args.front();
    const int width = intOption(args, "--width", 640);
    const int height = intOption(args, "--height", cmd == "render" ? width * 3 / 4 : 480);
    double bytes = double(width) * height * 400.0;
    std::error_code ec;
    if (args.size() > 1 && fs::is_regular_file(args[1], ec)) {  // a scene; not a session folder
        const auto size = fs::file_size(args[1], ec);
        if (!ec) bytes += 8.0 * double(size);
    }
    if (cmd == "bench" || cmd == "replay")
        bytes += double(width) * height * 1000.0;                            // G-buffers, images
    const double mb = std::min(bytes / 1048576.0 + 512.0, double(1 << 24));  // --mem's limit
    return int((mb + 255.0) / 256.0) * 256;
}

std::string selfExecutable() {
    std::error_code ec;
    const fs::path p = fs::read_symlink("/proc/self/exe", ec);
    return ec ? std::string("mirage") : p.string();
}

// Runs `argv` and returns its standard output; throws if it fails.
std::string runCapture(const std::vector<std::string>& argv) {
    std::string line;
    for (const auto& a : argv) line += (line.empty() ? "" : " ") + quote(a);
    FILE* pipe = ::popen((line + " 2>&1").c_str(), "r");
    if (!pipe) throw Error("mirage slurm: cannot run " + argv.front());
    std::string out;
    char buf[512];
    while (size_t n = std::fread(buf, 1, sizeof buf, pipe)) out.append(buf, n);
    const int status = ::pclose(pipe);
    if (status != 0) {
        const bool missing = WIFEXITED(status) && WEXITSTATUS(status) == 127;
        throw Error(fmt::format("mirage slurm: `{}` failed{}: {}", line,
                                missing ? " (sbatch not found: is this a Slurm login node? "
                                          "--sbatch PATH names it)"
                                        : "",
                                out));
    }
    while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
    return out;
}

std::string header(const SlurmArgs& a, const std::string& name, const fs::path& logs,
                   const std::string& logPattern, int cpus, int memoryMb) {
    std::string s = "#!/bin/bash\n";
    s += fmt::format("#SBATCH --job-name={}\n", name);
    s += fmt::format("#SBATCH --output={}\n", quote((logs / logPattern).string()));
    s += fmt::format("#SBATCH --cpus-per-task={}\n", cpus);
    s += fmt::format("#SBATCH --mem={}M\n", memoryMb);
    s += fmt::format("#SBATCH --time={}\n", a.timeLimit);
    if (!a.partition.empty()) s += fmt::format("#SBATCH --partition={}\n", a.partition);
    if (!a.account.empty()) s += fmt::format("#SBATCH --account={}\n", a.account);
    return s;
}

void run(const SlurmArgs& a) {
    if (a.command.empty())
        throw Error(
            "mirage slurm: give the command after --, e.g. mirage slurm --shards 4 -- synth "
            "scene.gltf -o session --seconds 60");
    const std::string& cmd = a.command.front();
    if (cmd != "synth" && cmd != "render" && cmd != "bench" && cmd != "replay")
        throw Error("mirage slurm: '" + cmd +
                    "' cannot be split; synth, render, bench and replay can (docs/scale.md)");
    const std::vector<std::string> args(a.command.begin() + 1, a.command.end());
    if (!optionValue(args, "--shard").empty())
        throw Error("mirage slurm: leave --shard out; each task gets its own");
    const std::string output = optionValue(args, "--output", "-o");
    if (output.empty()) throw Error("mirage slurm: the command needs -o OUT");
    const fs::path out = fs::absolute(output).lexically_normal();
    fs::path scripts = out;
    scripts += ".slurm";
    const fs::path logs = scripts / "logs";
    outputTarget(scripts, "mirage slurm", /*outIsFolder=*/true);
    outputTarget(out, "mirage slurm", fs::is_directory(out));
    fs::create_directories(logs);

    const int memoryMb = a.memoryMb > 0 ? a.memoryMb : estimateMemoryMb(a.command);
    const std::string mirage = a.mirage.empty() ? selfExecutable() : a.mirage;
    // Relative paths in the command are resolved from here, on every node.
    const fs::path workdir = fs::current_path();

    std::string task = header(a, "mirage-" + cmd, logs, "%A_%a.out", a.cpus, memoryMb);
    task += fmt::format("#SBATCH --array=0-{}\n", a.shards - 1);
    task += "set -euo pipefail\n";
    task += "cd " + quote(workdir.string()) + "\n";
    task += quote(mirage) + " " + cmd;
    for (const auto& arg : args) task += " " + quote(arg);
    if ((cmd == "synth" || cmd == "render") && optionValue(args, "--threads").empty())
        task += " --threads \"${SLURM_CPUS_PER_TASK:-1}\"";
    task += fmt::format(" --shard \"${{SLURM_ARRAY_TASK_ID}}/{}\"\n", a.shards);

    std::string merge = header(a, "mirage-merge", logs, "merge_%j.out", 1, 1024);
    merge += "set -euo pipefail\n";
    merge += "cd " + quote(workdir.string()) + "\n";
    merge += quote(mirage) + " merge " + quote(out.string()) + "\n";

    const fs::path taskScript = scripts / "shards.sbatch", mergeScript = scripts / "merge.sbatch";
    // Regenerated on every run (core/OutputFile.h: never over a special file, whole or not at all).
    for (const auto& [path, text] : {std::pair{taskScript, task}, std::pair{mergeScript, merge}}) {
        OutputFile script(path, OutputOrigin::Derived, OutputRule{{}, true, "mirage slurm"});
        std::ofstream o(script.temp());
        o << text;
        closeChecked(o, path);
        script.commit();
    }
    fs::permissions(taskScript, fs::perms::owner_exec, fs::perm_options::add);
    fs::permissions(mergeScript, fs::perms::owner_exec, fs::perm_options::add);

    std::printf(
        "mirage slurm: %d tasks of `mirage %s`, %d CPUs and %d MB each (%s), time limit %s\n",
        a.shards, cmd.c_str(), a.cpus, memoryMb,
        a.memoryMb > 0 ? "--mem" : "estimated; --mem sets it", a.timeLimit.c_str());
    std::printf("  scripts: %s, %s\n  logs:    %s/\n", taskScript.c_str(), mergeScript.c_str(),
                logs.c_str());
    if (a.dryRun) {
        std::printf(
            "  --dry-run: nothing submitted. Submit with:\n    %s --parsable %s\n"
            "    %s --dependency=afterok:<array job id> %s\n",
            a.sbatch.c_str(), taskScript.c_str(), a.sbatch.c_str(), mergeScript.c_str());
        return;
    }
    const std::string arrayJob = runCapture({a.sbatch, "--parsable", taskScript.string()});
    const std::string arrayId = arrayJob.substr(0, arrayJob.find(';'));
    const std::string mergeJob =
        runCapture({a.sbatch, "--parsable", "--kill-on-invalid-dep=yes",
                    "--dependency=afterok:" + arrayId, mergeScript.string()});
    const std::string mergeId = mergeJob.substr(0, mergeJob.find(';'));
    std::printf(
        "  submitted: array job %s (tasks 0-%d), merge job %s (starts when every task succeeded)\n"
        "  follow:    squeue -j %s,%s   |   scontrol show job %s   |   tail %s/%s_*.out\n"
        "  a failed task: the merge job is cancelled; rerun the task alone and merge again:\n"
        "    %s --array=<task> %s   then   %s --dependency=afterok:<new id> %s\n"
        "  the result: %s (after the merge)\n",
        arrayId.c_str(), a.shards - 1, mergeId.c_str(), arrayId.c_str(), mergeId.c_str(),
        arrayId.c_str(), logs.c_str(), arrayId.c_str(), a.sbatch.c_str(), taskScript.c_str(),
        a.sbatch.c_str(), mergeScript.c_str(), out.c_str());
    std::fflush(stdout);
}

const CommandRegistrar reg("slurm", [](CLI::App& parent) {
    auto* cmd = parent.add_subcommand("slurm",
                                      "Run synth, render, bench or replay on a Slurm cluster: a "
                                      "job array of --shards tasks and a "
                                      "merge job (docs/scale.md)");
    auto a = std::make_shared<SlurmArgs>();
    cmd->add_option("--shards", a->shards, "Tasks in the job array (one shard each)")
        ->required()
        ->check(wholeIn(1, 100000));
    cmd->add_option("--cpus", a->cpus, "CPUs per task (the command's --threads follows it)")
        ->capture_default_str()
        ->check(wholeIn(1, 4096));
    cmd->add_option("--mem", a->memoryMb, "Memory per task in MB (default: estimated)")
        ->check(wholeIn(1, 1 << 24));
    cmd->add_option("--time", a->timeLimit,
                    "Time limit per task (Slurm format: M, M:S, H:M:S, D-H, D-H:M or D-H:M:S, "
                    "e.g. 04:00:00)")
        ->capture_default_str()
        ->check(slurmTime());
    cmd->add_option("--partition", a->partition, "Slurm partition")->check(slurmName());
    cmd->add_option("--account", a->account, "Slurm account")->check(slurmName());
    cmd->add_option("--sbatch", a->sbatch, "The sbatch program")->capture_default_str();
    cmd->add_option("--mirage", a->mirage,
                    "The mirage binary the tasks run (default: this one; must be visible on "
                    "every node)");
    cmd->add_flag("--dry-run", a->dryRun, "Write the batch scripts and print them; submit nothing");
    cmd->add_option("command", a->command, "-- then synth|render|bench|replay and its arguments")
        ->expected(-1);
    cmd->callback([a] { run(*a); });
});

}  // namespace
}  // namespace mirage::app
