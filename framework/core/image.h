#pragma once
// A plain CPU image: row-major, row 0 at the top, one T per pixel.

#include <cassert>
#include <vector>

namespace rtlab {

template <class T>
struct Image {
    int width = 0;
    int height = 0;
    std::vector<T> pixels;

    Image() = default;
    Image(int w, int h, const T& fill = T{}) : width(w), height(h), pixels(std::size_t(w) * h, fill) {}

    T& at(int x, int y)
    {
        assert(x >= 0 && y >= 0 && x < width && y < height);
        return pixels[std::size_t(y) * width + x];
    }
    const T& at(int x, int y) const
    {
        assert(x >= 0 && y >= 0 && x < width && y < height);
        return pixels[std::size_t(y) * width + x];
    }
    std::size_t size() const { return pixels.size(); }
};

} // namespace rtlab
