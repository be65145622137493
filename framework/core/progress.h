#pragma once
// Progress reporting for long work. On a terminal: one bar redrawn in place with an ETA.
// Otherwise (CI logs, pipes): plain lines, at most one per `plainInterval` and one at the end.

#include <chrono>
#include <cstdio>
#include <string>

namespace rtlab {

class Progress {
public:
    //! `total` units of work, labelled `label`. `out` defaults to stderr.
    Progress(std::string label, std::size_t total, std::FILE* out = nullptr);
    ~Progress();

    //! Advance by `n` units; `detail` is shown beside the bar (e.g. the current run id).
    void advance(std::size_t n = 1, const std::string& detail = {});
    //! Print the final line (called by the destructor if not before).
    void finish();

    //! Force plain-line mode (tests) or terminal mode.
    void setInteractive(bool interactive) { mInteractive = interactive; }
    bool interactive() const { return mInteractive; }

    //! "1h02m", "3m05s", "12.3s".
    static std::string formatDuration(double seconds);
    //! The bar text for a state: "[#####.....] 5/10  50% ETA 3.0s  detail"; width 0 leaves out
    //! the bar itself (plain log lines).
    static std::string formatBar(std::size_t done, std::size_t total, double elapsedSeconds,
                                 const std::string& detail, int width = 30);

private:
    void draw(const std::string& detail, bool final);

    std::string mLabel;
    std::size_t mTotal;
    std::size_t mDone = 0;
    std::FILE* mOut;
    bool mInteractive;
    bool mFinished = false;
    std::chrono::steady_clock::time_point mStart;
    std::chrono::steady_clock::time_point mLastPlain;
    double mPlainInterval = 5.0;  //!< seconds between plain progress lines
    std::size_t mLastPlainDone = 0;  //!< progress shown by the last plain line
};

} // namespace rtlab
