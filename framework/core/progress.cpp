#include "core/progress.h"

#include <algorithm>
#include <unistd.h>

namespace rtlab {

Progress::Progress(std::string label, std::size_t total, std::FILE* out)
    : mLabel(std::move(label)), mTotal(total), mOut(out ? out : stderr),
      mStart(std::chrono::steady_clock::now()), mLastPlain(mStart)
{
    mInteractive = ::isatty(::fileno(mOut)) != 0;
    if (!mInteractive)
        std::fprintf(mOut, "%s: 0/%zu\n", mLabel.c_str(), mTotal);
}

Progress::~Progress()
{
    finish();
}

std::string Progress::formatDuration(double s)
{
    char buf[32];
    if (s < 60)
        std::snprintf(buf, sizeof buf, "%.1fs", s);
    else if (s < 3600)
        std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
    else
        std::snprintf(buf, sizeof buf, "%dh%02dm", int(s) / 3600, (int(s) % 3600) / 60);
    return buf;
}

std::string Progress::formatBar(std::size_t done, std::size_t total, double elapsed,
                                const std::string& detail, int width)
{
    const double frac = total ? std::min(1.0, double(done) / double(total)) : 1.0;
    std::string bar;
    if (width > 0) {
        const int filled = int(frac * width + 0.5);
        bar = "[" + std::string(filled, '#') + std::string(width - filled, '.') + "] ";
    }
    char buf[96];
    std::snprintf(buf, sizeof buf, "%zu/%zu %3d%%", done, total, int(frac * 100 + 0.5));
    bar += buf;
    if (done > 0 && done < total)
        bar += " ETA " + formatDuration(elapsed / double(done) * double(total - done));
    else if (done >= total)
        bar += " in " + formatDuration(elapsed);
    if (!detail.empty())
        bar += "  " + detail;
    return bar;
}

void Progress::advance(std::size_t n, const std::string& detail)
{
    mDone += n;
    draw(detail, false);
}

void Progress::draw(const std::string& detail, bool final)
{
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - mStart).count();
    if (mInteractive) {
        std::fprintf(mOut, "\r\033[2K%s %s", mLabel.c_str(),
                     formatBar(mDone, mTotal, elapsed, detail).c_str());
        if (final)
            std::fputc('\n', mOut);
        std::fflush(mOut);
        return;
    }
    const double sinceLast = std::chrono::duration<double>(now - mLastPlain).count();
    // The final line is not repeated when the last advance already printed the finished state.
    const bool due = final ? mLastPlainDone != mDone : sinceLast >= mPlainInterval;
    if (due) {
        mLastPlainDone = mDone;
        std::fprintf(mOut, "%s: %s\n", mLabel.c_str(),
                     formatBar(mDone, mTotal, elapsed, detail, 0).c_str());
        std::fflush(mOut);
        mLastPlain = now;
    }
}

void Progress::finish()
{
    if (mFinished)
        return;
    mFinished = true;
    draw({}, true);
}

} // namespace rtlab
