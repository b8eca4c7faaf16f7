#include "stageTimers.H"

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace Foam
{

const char* StageTimers::name(int s)
{
    static const char* names[NStages] =
    {
        "pack", "serialise", "send", "wait_dem", "receive", "unpack",
        "UEqn", "pEqn", "TEqn", "YEqn", "advance", "rest"
    };
    return names[s];
}


void StageTimers::endStep(double seconds)
{
    double staged = 0;
    for (int s = 0; s < Rest; ++s) staged += step_[s];
    step_[Rest] = seconds - staged;
    const double x = exchangeOf(step_);
    for (int s = 0; s < NStages; ++s)
    {
        total_[s] += step_[s];
        step_[s] = 0;
    }
    total_[NStages] += seconds;
    shareMin_ = steps_ == 0 ? x/seconds : std::min(shareMin_, x/seconds);
    shareMax_ = steps_ == 0 ? x/seconds : std::max(shareMax_, x/seconds);
    ++steps_;
}


std::string StageTimers::table(label nCells, bool direct) const
{
    const double n = std::max<long>(steps_, 1);
    const double all = total_[NStages];
    std::ostringstream os;
    char line[160];
    std::snprintf
    (
        line, sizeof line, "coredemFoam timers: %ld CFD steps, %d cells, %.3f s in steps, "
        "receive %s\n", steps_, int(nCells), all,
        direct ? "into the fields" : "by scatter copies"
    );
    os << line;
    std::snprintf(line, sizeof line, "  %-10s %12s %12s %8s\n", "stage", "total s", "ms/step",
        "share");
    os << line;
    for (int s = 0; s < NStages; ++s)
    {
        std::snprintf(line, sizeof line, "  %-10s %12.4f %12.4f %7.2f%%\n", name(s),
            total_[s], 1e3*total_[s]/n, all > 0 ? 100*total_[s]/all : 0.0);
        os << line;
    }
    std::snprintf(line, sizeof line, "  exchange (pack..unpack, incl. wait) %.2f%% of the step "
        "time (per step %.2f%%..%.2f%%); without the wait %.2f%%\n",
        all > 0 ? 100*exchangeOf(total_)/all : 0.0, 100*shareMin_, 100*shareMax_,
        all > 0 ? 100*ownOf(total_)/all : 0.0);
    os << line;
    return os.str();
}


std::string StageTimers::json(label nCells, bool direct) const
{
    const double n = std::max<long>(steps_, 1);
    const double all = total_[NStages];
    std::ostringstream os;
    os.precision(9);
    os << "{\n  \"participant\": \"coredemFoam\",\n  \"cells\": " << nCells
       << ",\n  \"steps\": " << steps_ << ",\n  \"receive_into_fields\": "
       << (direct ? "true" : "false") << ",\n  \"step_seconds\": " << all
       << ",\n  \"stages\": {";
    for (int s = 0; s < NStages; ++s)
    {
        os << (s ? "," : "") << "\n    \"" << name(s) << "\": {\"seconds\": " << total_[s]
           << ", \"per_step_s\": " << total_[s]/n << ", \"share\": "
           << (all > 0 ? total_[s]/all : 0.0) << "}";
    }
    os << "\n  },\n  \"exchange_share\": " << (all > 0 ? exchangeOf(total_)/all : 0.0)
       << ",\n  \"exchange_share_min\": " << shareMin_
       << ",\n  \"exchange_share_max\": " << shareMax_
       << ",\n  \"exchange_share_without_wait\": " << (all > 0 ? ownOf(total_)/all : 0.0)
       << "\n}\n";
    return os.str();
}

} // namespace Foam
