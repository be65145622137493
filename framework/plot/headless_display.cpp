#include "plot/headless_display.h"

#include "core/error.h"

#include <cctype>
#include <condition_variable>
#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <future>
#include <mutex>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

namespace rtlab::plot {

namespace {

constexpr int kStartTimeoutMs = 15000;
constexpr int kStopTimeoutMs = 3000;

std::string findXvfb()
{
    const char* path = std::getenv("PATH");
    std::string dirs = path ? path : "";
    dirs += ":/usr/bin:/usr/local/bin";
    std::size_t begin = 0;
    while (begin <= dirs.size()) {
        const std::size_t end = std::min(dirs.find(':', begin), dirs.size());
        const std::string candidate = dirs.substr(begin, end - begin) + "/Xvfb";
        if (end > begin && ::access(candidate.c_str(), X_OK) == 0)
            return candidate;
        begin = end + 1;
    }
    return {};
}

//! The display number of ":N", ":N.S", "unix:N[.S]"; -1 for anything else (remote displays).
int parseLocalDisplay(const std::string& display)
{
    const auto colon = display.find(':');
    if (colon == std::string::npos)
        return -1;
    const std::string host = display.substr(0, colon);
    if (!host.empty() && host != "unix")
        return -1;
    int number = 0;
    std::size_t i = colon + 1;
    if (i >= display.size() || !std::isdigit(static_cast<unsigned char>(display[i])))
        return -1;
    for (; i < display.size() && std::isdigit(static_cast<unsigned char>(display[i])); ++i)
        number = number * 10 + (display[i] - '0');
    return (i == display.size() || display[i] == '.') ? number : -1;
}

bool connectUnixSocket(const std::string& path, bool abstract)
{
    const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0)
        return false;
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    const std::size_t offset = abstract ? 1 : 0; // abstract names start with a NUL byte
    path.copy(address.sun_path + offset, sizeof(address.sun_path) - offset - 1);
    const auto length = socklen_t(offsetof(sockaddr_un, sun_path) + offset + path.size());
    const bool ok = ::connect(fd, reinterpret_cast<sockaddr*>(&address), length) == 0;
    ::close(fd);
    return ok;
}

bool isDisplayNumberReachable(int number)
{
    const std::string path = "/tmp/.X11-unix/X" + std::to_string(number);
    return connectUnixSocket(path, false) || connectUnixSocket(path, true);
}

} // namespace

struct XvfbServer::State {
    std::thread thread;
    std::mutex mutex;
    std::condition_variable wake;
    bool stop = false;
    pid_t pid = -1;
    int display = -1;
    std::promise<int> started; //!< the display number, or why the server did not start

    //! Body of the helper thread: start the server, report, wait for stop, end the server. The
    //! server's death signal is tied to this thread (PR_SET_PDEATHSIG).
    void run(const std::string& executable, int width, int height);
    void terminate();
};

void XvfbServer::State::run(const std::string& executable, int width, int height)
{
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) {
        started.set_exception(std::make_exception_ptr(EnvironmentError("pipe() failed")));
        return;
    }
    const int devNull = ::open("/dev/null", O_RDWR | O_CLOEXEC);
    // -noreset: by default an X server resets when its last client disconnects and refuses
    // connections meanwhile, which would fail the next figure (or the one after a probe).
    std::vector<std::string> args = {
        executable,  "-displayfd", std::to_string(fds[1]),
        "-screen",   "0",          std::to_string(width) + "x" + std::to_string(height) + "x24",
        "-nolisten", "tcp",        "-noreset"};
    std::vector<char*> argv;
    for (auto& a : args)
        argv.push_back(a.data());
    argv.push_back(nullptr);

    const pid_t parent = ::getpid();
    const pid_t child = ::fork();
    if (child == 0) {
        // Only async-signal-safe calls from here to exec.
        ::prctl(PR_SET_PDEATHSIG, SIGTERM);
        if (::getppid() != parent)
            ::_exit(1);
        if (devNull >= 0) {
            ::dup2(devNull, 0);
            ::dup2(devNull, 1);
            ::dup2(devNull, 2);
        }
        ::close_range(3, ~0U, CLOSE_RANGE_CLOEXEC); // keep nothing of ours open in the server
        ::fcntl(fds[1], F_SETFD, 0);
        ::execv(argv[0], argv.data());
        ::_exit(127);
    }
    ::close(fds[1]);
    if (devNull >= 0)
        ::close(devNull);
    if (child < 0) {
        ::close(fds[0]);
        started.set_exception(std::make_exception_ptr(EnvironmentError("fork() failed")));
        return;
    }
    pid = child;

    // Xvfb writes the display number it chose, then a newline, once it accepts connections.
    std::string text;
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::milliseconds(kStartTimeoutMs);
    while (text.find('\n') == std::string::npos) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
            deadline - std::chrono::steady_clock::now());
        pollfd p{fds[0], POLLIN, 0};
        if (left.count() <= 0 || ::poll(&p, 1, int(left.count())) <= 0)
            break;
        char buffer[32];
        const ssize_t n = ::read(fds[0], buffer, sizeof(buffer));
        if (n <= 0)
            break; // the server exited
        text.append(buffer, std::size_t(n));
    }
    ::close(fds[0]);
    const int number = text.find('\n') != std::string::npos
                           ? parseLocalDisplay(":" + text.substr(0, text.find('\n')))
                           : -1;
    bool reachable = false;
    for (int i = 0; number >= 0 && i < 100 && !(reachable = isDisplayNumberReachable(number)); ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (!reachable) {
        terminate();
        started.set_exception(std::make_exception_ptr(
            EnvironmentError("Xvfb (" + executable +
                             ") did not start; plots need an X display. Install the Debian "
                             "package xvfb or set DISPLAY to a running X server")));
        return;
    }
    display = number;
    started.set_value(number);

    std::unique_lock lock(mutex);
    wake.wait(lock, [this] { return stop; });
    terminate();
}

void XvfbServer::State::terminate()
{
    if (pid <= 0)
        return;
    ::kill(pid, SIGTERM);
    for (int waited = 0; waited < kStopTimeoutMs; waited += 10) {
        if (::waitpid(pid, nullptr, WNOHANG) != 0) {
            pid = -1;
            return;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
    pid = -1;
}

XvfbServer::XvfbServer(int width, int height) : mState(std::make_unique<State>())
{
    const std::string executable = findXvfb();
    if (executable.empty())
        throw EnvironmentError("Xvfb was not found; plots need an X display. Install the Debian "
                               "package xvfb or set DISPLAY to a running X server");
    auto result = mState->started.get_future();
    mState->thread = std::thread([state = mState.get(), executable, width, height] {
        state->run(executable, width, height);
    });
    try {
        result.get();
    } catch (...) {
        mState->thread.join();
        throw;
    }
}

XvfbServer::~XvfbServer()
{
    {
        std::lock_guard lock(mState->mutex);
        mState->stop = true;
    }
    mState->wake.notify_all();
    mState->thread.join();
}

int XvfbServer::getDisplayNumber() const
{
    return mState->display;
}

std::string XvfbServer::getDisplayName() const
{
    return ":" + std::to_string(mState->display);
}

int XvfbServer::getProcessId() const
{
    return int(mState->pid);
}

bool isLocalDisplayReachable(const std::string& display)
{
    const int number = parseLocalDisplay(display);
    return number >= 0 && isDisplayNumberReachable(number);
}

namespace {

std::mutex gDisplayMutex;

std::unique_ptr<XvfbServer>& getOwnServer()
{
    static std::unique_ptr<XvfbServer> server; // stopped by static destruction at exit
    return server;
}

} // namespace

std::string ensureDisplay()
{
    std::lock_guard lock(gDisplayMutex);
    const char* current = std::getenv("DISPLAY");
    if (current && *current) {
        const std::string display = current;
        if (parseLocalDisplay(display) < 0 || isLocalDisplayReachable(display))
            return display;
    }
    auto& server = getOwnServer();
    if (!server)
        server = std::make_unique<XvfbServer>();
    const std::string name = server->getDisplayName();
    ::setenv("DISPLAY", name.c_str(), 1);
    return name;
}

int getOwnXvfbDisplay()
{
    std::lock_guard lock(gDisplayMutex);
    const auto& server = getOwnServer();
    return server ? server->getDisplayNumber() : -1;
}

} // namespace rtlab::plot
