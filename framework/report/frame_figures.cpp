// Figures of the lit frame (runs with `frame: {lighting: true}`, experiment/lit_frame.h): frame
// time against final-frame error, the stacked time of every pass per frame, a filmstrip (frames x
// technique with the truth and error maps), and culling on against off, with the check that the
// final frames are bitwise the same.

#include "report/report_detail.h"

#include "experiment/image_files.h"
#include "plot/charts.h"
#include "plot/image_grid.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

namespace rtlab::report::detail {

namespace {

std::string getText(const experiment::Row& row, const std::string& column)
{
    auto it = row.find(column);
    return it == row.end() ? std::string() : it->second;
}

bool isCullingOff(const RunSummary& run)
{
    return getText(run.frames.front(), "frame.culling") == "false";
}

//! The first run of a technique with culling on (the frame figures show it).
const RunSummary* findFirstCulledRun(const std::vector<const RunSummary*>& runs)
{
    for (const RunSummary* r : runs)
        if (!isCullingOff(*r))
            return r;
    return nullptr;
}

std::vector<std::string> splitList(const std::string& text)
{
    std::vector<std::string> out;
    std::stringstream in(text);
    for (std::string item; std::getline(in, item, ';');)
        if (!item.empty())
            out.push_back(item);
    return out;
}

std::string formatMs(double ms)
{
    char text[32];
    std::snprintf(text, sizeof text, "%.1f", ms);
    return text;
}

} // namespace

Figures writeLitFrameFigures(const Group& group, const std::string& directory,
                             const plot::ColorTable& colors)
{
    Figures figures;
    bool lit = false;
    for (const auto& run : group.runs)
        lit = lit || std::isfinite(run.get("frame.rmse"));
    if (!lit)
        return figures;
    const std::string plots = directory + "/plots";
    const std::string stem = makeFileName(group.key);
    std::map<std::string, std::vector<const RunSummary*>> byTechnique;
    for (const auto& run : group.runs)
        byTechnique[run.technique].push_back(&run);

    // 1. Frame time against final-frame error, Pareto front per technique.
    plot::ScatterSpec scatter;
    scatter.title = group.title + ": lit frame, time against error";
    scatter.xLabel = "time of the frame's passes (ms per frame, CPU wall time, median of repeats)";
    scatter.yLabel = "final frame RMSE against Embree full radiance";
    scatter.colors = colors;
    for (const auto& [technique, runs] : byTechnique) {
        plot::Series s{technique};
        for (const RunSummary* run : runs) {
            s.x.push_back(run->get("frame.cpu_ms"));
            s.y.push_back(run->get("frame.rmse"));
            s.pointLabels.push_back(std::string(isCullingOff(*run) ? "culling off " : "") +
                                    describeRun(*run, group.varyingParams));
        }
        scatter.series.push_back(std::move(s));
    }
    plot::writeScatter(scatter, plots + "/frame_time_vs_error_" + stem);
    figures.plots.push_back(plots + "/frame_time_vs_error_" + stem);
    figures.captions.push_back(
        "Lit frame on " + group.title +
        ": mean time of the passes that make a frame against the final frame's RMSE "
        "(HDR radiance) against the Embree full radiance, averaged over the frames.");

    // 2. Per technique (its first run with culling on): every frame's passes, stacked.
    for (const auto& [technique, runs] : byTechnique) {
        const RunSummary* run = findFirstCulledRun(runs);
        if (!run)
            continue;
        plot::StackedBarSpec bars;
        bars.title = group.title + ": " + technique + ", time of each pass per frame";
        bars.yLabel = "CPU wall time (ms, median of repeats; 0 = skipped)";
        std::vector<std::string> passes;
        for (const auto& frame : run->frames)
            for (const auto& p : splitList(getText(frame, "frame_passes")))
                if (std::find(passes.begin(), passes.end(), p) == passes.end())
                    passes.push_back(p);
        bars.passes = passes;
        for (const auto& frame : run->frames) {
            bars.bars.push_back("frame " + getText(frame, "frame"));
            std::vector<double> values;
            for (const auto& p : passes) {
                const double v = experiment::getNumber(frame, p + ".cpu_ms");
                values.push_back(std::isfinite(v) ? v : 0.0);
            }
            bars.values.push_back(values);
        }
        if (bars.bars.empty() || passes.empty())
            continue;
        const std::string path = plots + "/frame_passes_" + makeFileName(technique) + "_" + stem;
        plot::writeStackedBars(bars, path);
        figures.plots.push_back(path);
        figures.captions.push_back(
            "Time of every pass that makes the frame, per frame, for " + technique + " on " +
            group.title + ". A pass that was skipped (reused work, nothing changed) is 0.");

        // The same passes' traffic over the bus (gpu/bus_counters.h): per frame one bar of what
        // went up and one of what came back, stacked by pass.
        plot::StackedBarSpec bus;
        bus.title = group.title + ": " + technique + ", bytes over the bus per pass";
        bus.yLabel = "MiB per frame (up: uploaded, down: read back)";
        bus.passes = passes;
        double total = 0.0;
        for (const auto& frame : run->frames)
            for (const char* direction : {"upload", "readback"}) {
                bus.bars.push_back("f" + getText(frame, "frame") +
                                   (std::string(direction) == "upload" ? " up" : " down"));
                std::vector<double> values;
                for (const auto& p : passes) {
                    const double v = experiment::getNumber(frame, p + "." + direction + "_bytes");
                    values.push_back(std::isfinite(v) ? v / 1048576.0 : 0.0);
                    total += values.back();
                }
                bus.values.push_back(values);
            }
        if (total > 0.0) {
            const std::string busPath = plots + "/frame_bus_" + makeFileName(technique) + "_" + stem;
            plot::writeStackedBars(bus, busPath);
            figures.plots.push_back(busPath);
            figures.captions.push_back(
                "What crosses the bus between host and device in every pass that makes the frame, "
                "per frame, for " + technique + " on " + group.title +
                " (uploads and read-backs, staged or mapped; <pass>.upload_bytes, "
                "<pass>.readback_bytes).");
        }
    }

    // 2b. What the frame's light is made of (experiment/lit_frame.cpp metric.frame_terms): per
    //     run with culling on, the mean radiance of each term over the surface pixels and the
    //     frames, the technique's bar beside the truth's, so an error is traced to its term.
    {
        static const char* kTerms[] = {"emission", "point_lights", "sky", "indirect"};
        plot::StackedBarSpec bars;
        bars.title = group.title + ": what the lit frame is made of";
        bars.yLabel = "mean radiance over the surface pixels (luminance)";
        bars.passes = {"emission", "point lights", "sky and emitters", "indirect"};
        bars.totalDecimals = 3;
        for (const auto& run : group.runs) {
            if (isCullingOff(run) || !std::isfinite(run.get("frame.term.sky")))
                continue;
            const std::string label = describeRun(run, group.varyingParams);
            const std::string sky = getText(run.frames.front(), "frame.sky");
            for (const char* side : {"frame", "truth"}) {
                bars.bars.push_back(std::string(side) == "truth"
                                        ? "truth (" + run.technique + (label.empty() ? "" : " " + label) + ")"
                                        : run.technique + (label.empty() ? "" : " " + label) +
                                              (sky.empty() ? "" : " sky=" + sky));
                std::vector<double> values;
                for (const char* term : kTerms) {
                    const double v = run.get(std::string(side) + ".term." + term);
                    values.push_back(std::isfinite(v) ? v : 0.0);
                }
                bars.values.push_back(values);
            }
        }
        if (!bars.bars.empty()) {
            const std::string key = numberBarsThatDoNotFit(bars);
            const std::string path = plots + "/frame_terms_" + stem;
            plot::writeStackedBars(bars, path);
            figures.plots.push_back(path);
            figures.captions.push_back(
                "What the lit frame is made of on " + group.title +
                ", per run and beside the Embree truth of the same frames: the mean radiance of "
                "emission, point lights, the sky (with the emitters' light, which the truth and "
                "the cones' sky carry) and indirect light over the surface pixels, averaged over "
                "the frames." + key);
        }
    }

    // 3. Culling on against off: total time, and whether the final frames are bitwise the same.
    {
        plot::StackedBarSpec bars;
        bars.title = group.title + ": culling on against off";
        bars.yLabel = "time of all frames (ms, sum over frames)";
        bars.passes = {"frames"};
        std::string notes;
        for (const auto& [technique, runs] : byTechnique) {
            const RunSummary* on = nullptr;
            const RunSummary* off = nullptr;
            for (const RunSummary* r : runs) {
                if (isCullingOff(*r)) {
                    if (!off)
                        off = r;
                } else if (!on) {
                    on = r;
                }
            }
            if (!on || !off)
                continue;
            auto total = [](const RunSummary& r) {
                double sum = 0.0;
                for (const auto& f : r.frames) {
                    const double v = experiment::getNumber(f, "frame.cpu_ms");
                    sum += std::isfinite(v) ? v : 0.0;
                }
                return sum;
            };
            const double tOn = total(*on), tOff = total(*off);
            // The work culling removed, measured directly: the time the run without culling spent
            // in frame passes that the run with culling skipped in the same frame (robust to the
            // timing noise of the passes both ran).
            double skippedWork = 0.0;
            for (std::size_t k = 0; k < std::min(on->frames.size(), off->frames.size()); ++k) {
                const std::string passesOn = getText(on->frames[k], "passes");
                for (const auto& p : splitList(getText(off->frames[k], "frame_passes")))
                    if (passesOn.find(p + ":skipped(") != std::string::npos) {
                        const double v = experiment::getNumber(off->frames[k], p + ".cpu_ms");
                        skippedWork += std::isfinite(v) ? v : 0.0;
                    }
            }
            bars.bars.push_back(technique + "\nculling on");
            bars.values.push_back({tOn});
            bars.bars.push_back(technique + "\nculling off");
            bars.values.push_back({tOff});
            // Bitwise comparison of the final HDR frames, frame by frame.
            int same = 0, compared = 0;
            for (std::size_t k = 0; k < std::min(on->frames.size(), off->frames.size()); ++k) {
                const std::string a = getText(on->frames[k], "image.lit_hdr");
                const std::string b = getText(off->frames[k], "image.lit_hdr");
                if (a.empty() || b.empty() || !std::filesystem::exists(a) ||
                    !std::filesystem::exists(b))
                    continue;
                ++compared;
                const auto ia = experiment::readExrRgb(a), ib = experiment::readExrRgb(b);
                same += ia.width == ib.width && ia.height == ib.height &&
                        std::memcmp(ia.pixels.data(), ib.pixels.data(),
                                    ia.pixels.size() * sizeof(glm::vec3)) == 0;
            }
            notes += (notes.empty() ? "" : "; ") + technique + ": " + formatMs(tOn) +
                     " ms with culling, " + formatMs(tOff) +
                     " ms without; the passes culling skipped took " + formatMs(skippedWork) +
                     " ms (" + formatMs(100.0 * skippedWork / tOff) +
                     " % of the frames without culling); " + std::to_string(same) + " of " +
                     std::to_string(compared) + " final frames bitwise identical";
        }
        if (!bars.bars.empty()) {
            const std::string path = plots + "/frame_culling_" + stem;
            plot::writeStackedBars(bars, path);
            figures.plots.push_back(path);
            figures.captions.push_back("Culling on against off on " + group.title +
                                       " (sum of the frames' pass times): " + notes + ".");
        }
    }

    // 4. Filmstrip: the truth and each technique's tonemapped frames (culling on), then each
    //    technique's |HDR error| per frame.
    plot::ImageGridSpec grid;
    grid.title = group.title + ": frames and |error|"; // the caption says the rest
    grid.encodeSrgb = false; // the PNGs are display values already
    grid.errorLabel = "mean |HDR error| over channels (radiance)";
    std::vector<std::vector<plot::GridCell>> imageRows, errorRows;
    std::vector<std::string> imageTitles, errorTitles;
    std::size_t frameCount = 0;
    // Row titles without what every technique shares ("bentcone_ssdo+" in front of each voxel GI
    // technique): they are drawn rotated beside one image's height.
    std::string shared;
    for (const auto& [technique, runs] : byTechnique) {
        const std::string prefix = technique.substr(0, technique.rfind('+') + 1);
        shared = shared.empty() || shared == prefix ? prefix : "-";
    }
    if (shared == "-")
        shared.clear();
    for (const auto& [technique, runs] : byTechnique) {
        // The technique's first run with culling on, and among those one whose lit frame takes
        // the technique's own sky where there is one (`frame: {sky: lobes}` is the frame's
        // ablation, not the technique's frame).
        const auto lobes = [](const RunSummary* r) {
            const auto it = r->text.find("frame.sky");
            return it != r->text.end() && it->second == "lobes";
        };
        const RunSummary* run = nullptr;
        for (const RunSummary* r : runs)
            if (!isCullingOff(*r) && (!run || (lobes(run) && !lobes(r))))
                run = r;
        if (!run)
            continue;
        std::vector<plot::GridCell> images, errors, truths;
        for (const auto& frame : run->frames) {
            const std::string png = getText(frame, "image.lit"),
                              hdr = getText(frame, "image.lit_hdr");
            const std::string truthPng = getText(frame, "image.truth"),
                              truthHdr = getText(frame, "image.truth_hdr");
            if (png.empty() || !std::filesystem::exists(png) || !std::filesystem::exists(truthHdr))
                break;
            images.push_back(plot::makeColorCell(experiment::readPngRgb(png)));
            errors.push_back(plot::makeErrorCell(plot::computeAbsoluteErrorMap(
                experiment::readExrRgb(hdr), experiment::readExrRgb(truthHdr))));
            if (imageRows.empty())
                truths.push_back(plot::makeColorCell(experiment::readPngRgb(truthPng)));
        }
        if (images.empty() || (frameCount && images.size() != frameCount))
            continue;
        frameCount = images.size();
        if (imageRows.empty()) {
            imageRows.push_back(truths);
            imageTitles.push_back("Embree full");
        }
        const std::string title = technique.substr(shared.size());
        imageRows.push_back(images);
        imageTitles.push_back(title);
        errorRows.push_back(errors);
        errorTitles.push_back("|error| " + title);
    }
    if (imageRows.size() > 1) {
        for (std::size_t k = 0; k < frameCount; ++k)
            grid.columnTitles.push_back("frame " + std::to_string(k));
        grid.rows = imageRows;
        grid.rows.insert(grid.rows.end(), errorRows.begin(), errorRows.end());
        grid.rowTitles = imageTitles;
        grid.rowTitles.insert(grid.rowTitles.end(), errorTitles.begin(), errorTitles.end());
        const std::string path = plots + "/filmstrip_" + stem;
        plot::writeImageGrid(grid, path);
        figures.plots.push_back(path);
        figures.captions.push_back(
            "Filmstrip of " + group.title +
            ": the Embree full radiance and each technique's lit frame (tonemapped), "
            "then each technique's absolute HDR error, frame by frame" +
            (shared.empty() ? std::string() : " (every row with " + shared.substr(0, shared.size() - 1) + ")") +
            "; each technique's first run with culling on whose frame takes the technique's own "
            "sky.");
    }
    return figures;
}

} // namespace rtlab::report::detail
