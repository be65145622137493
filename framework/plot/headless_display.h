#pragma once
// X display for rendering without a screen. This VTK build draws with OpenGL through X (no EGL or
// OSMesa), so when there is no usable $DISPLAY the plot writers start a private Xvfb (Mesa's
// llvmpipe then provides OpenGL) and point $DISPLAY at it for the rest of the process.

#include <memory>
#include <string>

namespace rtlab::plot {

//! A private Xvfb server for as long as the object lives.
//!
//! Xvfb picks a free display number itself (-displayfd), so concurrent processes do not collide.
//! It is started from a helper thread that lives as long as this object and the server gets
//! SIGTERM when that thread ends, so it also goes away when the process dies abnormally.
class XvfbServer {
public:
    //! Starts `Xvfb -screen 0 <width>x<height>x24 -nolisten tcp -noreset` and waits until its
    //! socket /tmp/.X11-unix/X<N> accepts connections. Throws rtlab::EnvironmentError (naming the
    //! xvfb package) when it does not start within a few seconds.
    explicit XvfbServer(int width = 1920, int height = 1080);
    //! Stops the server (SIGTERM) and waits for it to exit.
    ~XvfbServer();
    XvfbServer(const XvfbServer&) = delete;
    XvfbServer& operator=(const XvfbServer&) = delete;

    int getDisplayNumber() const;
    //! ":<N>".
    std::string getDisplayName() const;
    //! Process id of the server.
    int getProcessId() const;

private:
    struct State;
    std::unique_ptr<State> mState;
};

//! Makes sure X rendering can work and returns the display in use. If $DISPLAY names a local
//! server that accepts connections (or a remote one, which is not probed) it is kept; otherwise
//! a process-wide XvfbServer is started once, $DISPLAY is set to it, and it is stopped at exit.
//! The plot writers call this; call it early if other threads read the environment.
std::string ensureDisplay();

//! The display number of the process-wide Xvfb that ensureDisplay() started, or -1 if none.
int getOwnXvfbDisplay();

//! Whether a local X display such as ":3" or ":3.0" accepts connections on its socket.
bool isLocalDisplayReachable(const std::string& display);

} // namespace rtlab::plot
