#pragma once
// Errors with source locations. Every error caused by user input (configs, scenes, meshes, CLI
// arguments) is an InputError that names the file, line and column and says what was expected.

#include <stdexcept>
#include <string>

namespace rtlab {

//! A position in a user-supplied file. Lines and columns are 1-based; 0 means "unknown".
struct SourceLocation {
    std::string file;  //!< path as the user gave it
    int line = 0;      //!< 1-based, 0 if unknown
    int column = 0;    //!< 1-based, 0 if unknown

    //! "file:line:column", leaving out the parts that are unknown.
    std::string toString() const;
};

//! Base class of all rtlab errors.
class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
};

//! Bad user input. what() reads "file:line:column: error: message".
class InputError : public Error {
public:
    InputError(SourceLocation where, const std::string& message);

    const SourceLocation& location() const { return mWhere; }
    const std::string& message() const { return mMessage; }

private:
    SourceLocation mWhere;
    std::string mMessage;
};

//! A resource the run needs is not available (no Vulkan device, missing package, ...).
class EnvironmentError : public Error {
public:
    explicit EnvironmentError(const std::string& message) : Error(message) {}
};

} // namespace rtlab
