#include "core/error.h"

namespace rtlab {

std::string SourceLocation::toString() const
{
    std::string s = file.empty() ? std::string("<input>") : file;
    if (line > 0) {
        s.append(1, ':').append(std::to_string(line));
        if (column > 0)
            s.append(1, ':').append(std::to_string(column));
    }
    return s;
}

static std::string formatInputError(const SourceLocation& where, const std::string& message)
{
    return where.toString() + ": error: " + message;
}

InputError::InputError(SourceLocation where, const std::string& message)
    : Error(formatInputError(where, message)), mWhere(std::move(where)), mMessage(message)
{
}

} // namespace rtlab
