#pragma once
// The measured speed-vs-error table a frame-time governor chooses from: one row per quality
// setting (the governed knobs' values, render/governor/GovernedKnobs.h) with its frame time and
// its error against ground truth, as `mirage bench` measures them (its bench.csv rows: knob
// columns, `wall_ms`, `psnr_influenced_db`). Times are of the machine and scene the table was
// measured on; the governor scales them by what it measures (FrameBudgetGovernor).
#include <string>
#include <vector>

#include "render/governor/GovernedKnobs.h"

namespace mirage::render {

struct SpeedErrorRow {
    QualitySetting setting;
    double frameMs = 0;  // median frame time (ms) where it was measured
    double psnrDb = 0;   // PSNR over the pixels the virtual objects influence (dB; higher: better)
};

class SpeedErrorTable {
public:
    SpeedErrorTable() = default;
    explicit SpeedErrorTable(std::vector<SpeedErrorRow> rows);

    // Reads a `mirage bench` bench.csv (or any CSV with those columns): the governed knobs'
    // columns present in it, `wall_ms` (else `gpu_ms`) and `psnr_influenced_db`; rows without a
    // time or an error (the footage-only row) are left out. Throws mirage::Error naming the file
    // and what is missing.
    static SpeedErrorTable readBenchCsv(const std::string& path);

    const std::vector<SpeedErrorRow>& rows() const { return rows_; }
    // The rows no other row beats in both time and error (faster-or-equal and at least as
    // accurate, one of them strictly), fastest first (so least accurate first). Never empty for a
    // non-empty table.
    std::vector<SpeedErrorRow> paretoFront() const;
    // Row `a` is worse than row `b` in both time and error.
    static bool dominated(const SpeedErrorRow& a, const SpeedErrorRow& b);

private:
    std::vector<SpeedErrorRow> rows_;
};

}  // namespace mirage::render
