#include "plot/figure.h"

#include "core/error.h"
#include "plot/headless_display.h"

#include <vtkAxis.h>
#include <vtkBrush.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkContext2D.h>
#include <vtkContextActor.h>
#include <vtkContextScene.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPDFExporter.h>
#include <vtkPNGWriter.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkStringArray.h>
#include <vtkTextProperty.h>
#include <vtkWindowToImageFilter.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

namespace rtlab::plot::detail {

namespace {

constexpr double kPadFraction = 0.05;

void styleText(vtkTextProperty* text, float size, bool bold)
{
    text->SetFontFamilyToArial();
    text->SetFontSize(std::max(1, int(std::lround(size))));
    text->SetBold(bold);
    text->SetItalic(false);
    text->SetShadow(false);
    text->SetColor(0.1, 0.1, 0.1);
}

//! Round tick positions covering [min, max], about `count` of them (1, 2 or 5 times a power of
//! ten apart), labelled with as many decimals as the step needs. VTK's own linear ticks get too
//! dense on large figures; its logarithmic ticks are fine and are kept.
void setLinearTicks(vtkAxis* axis, double min, double max, int count)
{
    const double raw = (max - min) / std::max(count, 1);
    if (!(raw > 0) || !std::isfinite(raw))
        return;
    const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
    const double fraction = raw / magnitude;
    const double step = magnitude * (fraction < 1.5 ? 1 : fraction < 3 ? 2 : fraction < 7 ? 5 : 10);
    const int decimals = std::max(0, int(-std::floor(std::log10(step) + 1e-9)));
    vtkNew<vtkDoubleArray> positions;
    vtkNew<vtkStringArray> labels;
    for (double k = std::ceil(min / step - 1e-9); k * step <= max + step * 1e-9; k += 1) {
        const double v = k * step;
        char text[64];
        if (decimals <= 6)
            std::snprintf(text, sizeof(text), "%.*f", decimals, v == 0 ? 0.0 : v);
        else
            std::snprintf(text, sizeof(text), "%g", v);
        positions->InsertNextValue(v);
        labels->InsertNextValue(text);
    }
    axis->SetCustomTickPositions(positions, labels);
}

void setupAxis(vtkAxis* axis, const AxisSetup& setup, float scale, int pixels)
{
    axis->SetTitle(setup.label);
    styleText(axis->GetTitleProperties(), 15 * scale, false);
    styleText(axis->GetLabelProperties(), 12 * scale, false);
    axis->GetGridPen()->SetColor(225, 225, 225, 255);
    axis->GetPen()->SetColor(60, 60, 60, 255);
    axis->SetLogScale(setup.log);
    axis->SetBehavior(vtkAxis::FIXED);
    axis->SetUnscaledRange(setup.min, setup.max);
    if (!setup.log)
        setLinearTicks(axis, setup.min, setup.max,
                       std::clamp(int(float(pixels) / (80.0f * scale)), 3, 10));
}

} // namespace

std::unique_lock<std::mutex> lockRendering()
{
    static std::mutex mutex;
    return std::unique_lock(mutex);
}

// A render window with one renderer showing one context actor; no interactor, which would only
// matter on screen (and vtkContextView's X interactor touches the display before it is ready).
struct Figure::Impl {
    vtkSmartPointer<vtkRenderWindow> window;
    vtkSmartPointer<vtkRenderer> renderer;
    vtkSmartPointer<vtkContextActor> actor;
};

Figure::Figure(int width, int height)
    : mImpl(std::make_unique<Impl>()), mWidth(width), mHeight(height)
{
    if (width < 16 || height < 16 || width > 16384 || height > 16384)
        throw Error("figure size " + std::to_string(width) + " x " + std::to_string(height) +
                    " is outside 16 .. 16384 pixels");
    ensureDisplay();
    mImpl->window = vtkSmartPointer<vtkRenderWindow>::New();
    mImpl->renderer = vtkSmartPointer<vtkRenderer>::New();
    mImpl->actor = vtkSmartPointer<vtkContextActor>::New();
    mImpl->window->SetOffScreenRendering(true);
    mImpl->window->SetMultiSamples(8);
    mImpl->window->SetSize(width, height);
    mImpl->window->AddRenderer(mImpl->renderer);
    mImpl->renderer->SetBackground(1.0, 1.0, 1.0);
    mImpl->renderer->AddActor(mImpl->actor);
}

Figure::~Figure() = default;

float Figure::getFontScale() const
{
    return std::max(0.5f, std::min(float(mWidth) / 1000.0f, float(mHeight) / 700.0f));
}

void Figure::addItem(vtkContextItem* item)
{
    mImpl->actor->GetScene()->AddItem(item);
}

void Figure::write(const std::string& pathWithoutExtension, const std::string& title)
{
    const std::filesystem::path base(pathWithoutExtension);
    if (base.has_parent_path())
        std::filesystem::create_directories(base.parent_path());
    const std::string png = pathWithoutExtension + ".png";
    const std::string pdf = pathWithoutExtension + ".pdf";
    std::filesystem::remove(png);
    std::filesystem::remove(pdf);

    vtkRenderWindow* window = mImpl->window;
    window->Render();
    vtkNew<vtkWindowToImageFilter> grab;
    grab->SetInput(window);
    grab->SetInputBufferTypeToRGB();
    grab->ReadFrontBufferOff();
    grab->Update();
    vtkNew<vtkPNGWriter> pngWriter;
    pngWriter->SetFileName(png.c_str());
    pngWriter->SetInputConnection(grab->GetOutputPort());
    pngWriter->Write();

    vtkNew<vtkPDFExporter> pdfWriter;
    pdfWriter->SetRenderWindow(window);
    pdfWriter->SetFileName(pdf.c_str());
    pdfWriter->SetTitle(title.c_str());
    pdfWriter->Write();

    for (const auto& file : {png, pdf})
        if (!std::filesystem::exists(file) || std::filesystem::file_size(file) == 0)
            throw Error("could not write " + file);
}

void computeAxisRange(const std::vector<double>& values, bool log, double& min, double& max)
{
    double lo = std::numeric_limits<double>::infinity();
    double hi = -lo;
    for (double v : values) {
        if (std::isfinite(v) && (!log || v > 0)) {
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
    }
    if (lo > hi) { // nothing to show
        min = log ? 1.0 : 0.0;
        max = log ? 10.0 : 1.0;
        return;
    }
    if (log) {
        double a = std::log10(lo), b = std::log10(hi);
        const double pad = std::max(b - a, 0.5) * kPadFraction + (b == a ? 0.25 : 0.0);
        min = std::pow(10.0, a - pad);
        max = std::pow(10.0, b + pad);
        return;
    }
    const double pad = hi > lo ? (hi - lo) * kPadFraction : std::max(std::abs(hi), 1.0) * 0.5;
    min = lo - pad;
    max = hi + pad;
    if (lo >= 0 && min < 0) // do not invent negative times or errors
        min = 0;
}

std::string wrapText(const std::string& text, std::size_t maxChars)
{
    std::string out, line;
    std::size_t start = 0;
    while (start <= text.size()) {
        std::size_t end = text.find(' ', start);
        if (end == std::string::npos)
            end = text.size();
        const std::string word = text.substr(start, end - start);
        if (!line.empty() && line.size() + 1 + word.size() > maxChars) {
            out += (out.empty() ? "" : "\n") + line;
            line = word;
        } else {
            line += (line.empty() ? "" : " ") + word;
        }
        start = end + 1;
    }
    if (!line.empty())
        out += (out.empty() ? "" : "\n") + line;
    return out;
}

vtkChartXY* addChart(Figure& figure, const std::string& title, const AxisSetup& x,
                     const AxisSetup& y)
{
    const float scale = figure.getFontScale();
    vtkNew<vtkChartXY> chart;
    figure.addItem(chart);
    // A long title wraps at spaces (18 px bold: about 0.6 em per character). VTK centres it over
    // the plot area, which a legend may narrow to its 600 px minimum (widenForLegend): the title
    // may pass that by the axis margin on either side, about 720 px in all.
    const float titleWidth = std::min(float(figure.getWidth() - 40), 720.0f * scale);
    const std::size_t maxChars = std::max<std::size_t>(20, std::size_t(titleWidth / (0.6f * 18.0f * scale)));
    chart->SetTitle(wrapText(title, maxChars));
    styleText(chart->GetTitleProperties(), 18 * scale, true);
    chart->SetAutoAxes(false);
    setupAxis(chart->GetAxis(vtkAxis::BOTTOM), x, scale, figure.getWidth());
    setupAxis(chart->GetAxis(vtkAxis::LEFT), y, scale, figure.getHeight());
    chart->GetAxis(vtkAxis::TOP)->SetVisible(false);
    chart->GetAxis(vtkAxis::RIGHT)->SetVisible(false);
    chart->SetShowLegend(true);
    vtkChartLegend* legend = chart->GetLegend();
    legend->SetInline(false);
    legend->SetHorizontalAlignment(vtkChartLegend::RIGHT);
    legend->SetVerticalAlignment(vtkChartLegend::TOP);
    legend->SetLabelSize(int(std::lround(13 * scale)));
    legend->GetBrush()->SetColor(255, 255, 255, 255);
    legend->GetPen()->SetColor(200, 200, 200, 255);
    return chart; // the scene holds the reference
}

void setPlotColor(vtkPlot* plot, Color color, unsigned char alpha)
{
    plot->GetPen()->SetColor(color.r, color.g, color.b, alpha);
    plot->GetBrush()->SetColor(color.r, color.g, color.b, alpha);
}

void setLineColor(vtkPlot* plot, Color color)
{
    plot->GetPen()->SetColor(color.r, color.g, color.b, 255);
    plot->GetBrush()->SetColor(color.r, color.g, color.b, 0);
}

void drawPixelTexts(vtkContext2D* painter, const std::vector<PixelText>& texts, int height)
{
    for (const PixelText& t : texts) {
        vtkTextProperty* prop = painter->GetTextProp();
        prop->SetFontFamilyToArial();
        prop->SetFontSize(int(std::lround(t.size)));
        prop->SetBold(t.bold);
        prop->SetItalic(false);
        prop->SetShadow(false);
        prop->SetColor(0.1, 0.1, 0.1);
        prop->SetJustification(t.justification);
        prop->SetVerticalJustificationToCentered();
        prop->SetOrientation(t.orientation);
        painter->DrawString(t.x, float(height) - t.y, t.text.c_str()); // within a pixel
    }
}

} // namespace rtlab::plot::detail
