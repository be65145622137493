#include "plot/headless_display.h"

#include <gtest/gtest.h>

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <string>

#include <signal.h>

using namespace rtlab::plot;

TEST(HeadlessTest, XvfbServerRunsForTheLifetimeOfTheObject)
{
    int pid = -1;
    std::string name;
    {
        XvfbServer server(640, 480);
        pid = server.getProcessId();
        name = server.getDisplayName();
        EXPECT_GE(server.getDisplayNumber(), 0);
        EXPECT_EQ(name, ":" + std::to_string(server.getDisplayNumber()));
        EXPECT_TRUE(isLocalDisplayReachable(name));
        EXPECT_EQ(::kill(pid, 0), 0);
    }
    errno = 0;
    EXPECT_EQ(::kill(pid, 0), -1);
    EXPECT_EQ(errno, ESRCH); // gone and reaped
    // Its display is free again: no X lock names the stopped server. A test running in parallel
    // may start a server on the freed number at any moment (also between two checks here), so
    // a reachable display is allowed as long as its lock names another process.
    const auto lockOwner = [&] {
        std::ifstream lock("/tmp/.X" + name.substr(1) + "-lock");
        int owner = -1;
        return lock >> owner ? owner : -1;
    };
    EXPECT_NE(lockOwner(), pid) << "the lock of " << name << " still names the stopped server";
    if (isLocalDisplayReachable(name)) {
        EXPECT_NE(lockOwner(), pid) << name << " is served by the stopped server";
    }
}

TEST(HeadlessTest, TwoServersGetDifferentDisplays)
{
    XvfbServer a(320, 240), b(320, 240);
    EXPECT_NE(a.getDisplayNumber(), b.getDisplayNumber());
}

TEST(HeadlessTest, EnsureDisplayStartsXvfbWhenDisplayIsUnset)
{
    ::unsetenv("DISPLAY");
    const std::string display = ensureDisplay();
    ASSERT_GE(getOwnXvfbDisplay(), 0);
    EXPECT_EQ(display, ":" + std::to_string(getOwnXvfbDisplay()));
    ASSERT_NE(std::getenv("DISPLAY"), nullptr);
    EXPECT_EQ(std::string(std::getenv("DISPLAY")), display);
    EXPECT_TRUE(isLocalDisplayReachable(display));
    // Later calls reuse it.
    EXPECT_EQ(ensureDisplay(), display);
}

TEST(HeadlessTest, EnsureDisplayReplacesADisplayNobodyServes)
{
    ::setenv("DISPLAY", ":9999", 1);
    ASSERT_FALSE(isLocalDisplayReachable(":9999"));
    const std::string display = ensureDisplay();
    EXPECT_NE(display, ":9999");
    EXPECT_TRUE(isLocalDisplayReachable(display));
    EXPECT_EQ(std::string(std::getenv("DISPLAY")), display);
}

TEST(HeadlessTest, EnsureDisplayKeepsADisplayThatIsServed)
{
    XvfbServer other(320, 240);
    ::setenv("DISPLAY", (other.getDisplayName() + ".0").c_str(), 1);
    EXPECT_EQ(ensureDisplay(), other.getDisplayName() + ".0");
    EXPECT_EQ(std::string(std::getenv("DISPLAY")), other.getDisplayName() + ".0");
    ::unsetenv("DISPLAY");
}

TEST(HeadlessTest, ParsesOnlyLocalDisplays)
{
    EXPECT_FALSE(isLocalDisplayReachable("remote.example:0"));
    EXPECT_FALSE(isLocalDisplayReachable(":"));
    EXPECT_FALSE(isLocalDisplayReachable("garbage"));
}
