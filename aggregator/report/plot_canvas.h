#pragma once
// A small plotting helper over OpenCV's drawing primitives (there is no plotting library in
// silnet): a data-to-pixel mapping for one rectangular panel of an image, with a framed
// plot area, "nice" ticks, tick labels, axis labels and a title, and markers, lines, bars
// and text in data coordinates. Several panels can share one image (grids of plots).

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace silnet::aggregator {

// Colours (BGR) shared by the report's plots.
namespace plot_colour {
inline const cv::Scalar kBackground(255, 255, 255);
inline const cv::Scalar kText(40, 40, 40);
inline const cv::Scalar kGrid(232, 232, 232);
inline const cv::Scalar kFrame(120, 120, 120);
inline const cv::Scalar kLight(190, 190, 190);
inline const cv::Scalar kBlue(180, 110, 30);
inline const cv::Scalar kRed(40, 40, 210);
inline const cv::Scalar kGreen(60, 160, 60);
}  // namespace plot_colour

// A white BGR image of the given size.
cv::Mat BlankImage(int width, int height);

// About `target` round tick values (1, 2 or 5 times a power of ten) covering [lo, hi].
std::vector<double> NiceTicks(double lo, double hi, int target = 5);

// A short label for a tick value ("0.25", "1e+03", "-3").
std::string TickLabel(double value);

// Green (t = 0) through yellow (0.5) to red (t >= 1); t is clamped to [0, 1].
cv::Scalar TrafficLight(double t);

// Where text is anchored relative to its point.
enum class TextAnchor { kLeft, kCentre, kRight };

// Draws `text` (Hershey simplex, scale 1 is 0.45 of OpenCV's) with its baseline at `at.y`,
// or vertically centred on it when `middle`, anchored horizontally by `anchor`; a non-null
// `background` fills the text's box first. Returns the box the text occupies.
cv::Rect DrawText(cv::Mat* image, const std::string& text, cv::Point2d at, double scale,
                  const cv::Scalar& colour, TextAnchor anchor = TextAnchor::kLeft,
                  bool middle = false, const cv::Scalar* background = nullptr);

// The box DrawText would fill, without drawing.
cv::Rect TextBox(const std::string& text, cv::Point2d at, double scale,
                 TextAnchor anchor = TextAnchor::kLeft, bool middle = false);

// A dashed line segment (dash and gap of `dash` pixels).
void DrawDashedLine(cv::Mat* image, cv::Point2d a, cv::Point2d b, const cv::Scalar& colour,
                    int thickness = 1, double dash = 6.0);

// One plot panel: `area` of an image, with margins for the labels around the plot area.
// The image is shared, not copied; draw the frame and ticks with DrawAxes after setting the
// ranges, then the data.
class PlotCanvas {
 public:
  // `font_scale` scales all text (1 = Hershey simplex at 0.45).
  PlotCanvas(cv::Mat image, cv::Rect area, double font_scale = 1.0);

  // The data ranges shown; an empty or inverted range is widened around its value.
  void SetRanges(double x_min, double x_max, double y_min, double y_max);
  // Widens one of the ranges so that a data unit spans the same pixels on both axes (for
  // maps and orthographic views).
  void MakeEqualAspect();

  // Grid, frame, ticks with labels, axis labels (either may be empty) and the title above.
  void DrawAxes(const std::string& x_label, const std::string& y_label);
  void DrawTitle(const std::string& title);
  // Text in the middle of the plot area (for "no data").
  void DrawMessage(const std::string& message);

  // Pixel position (in the image) of a data point; y grows upwards in data.
  cv::Point2d ToPixel(double x, double y) const;
  bool Contains(double x, double y) const;

  void Line(double x0, double y0, double x1, double y1, const cv::Scalar& colour,
            int thickness = 1) const;
  void Dot(double x, double y, int radius, const cv::Scalar& colour, bool filled = true) const;
  // Bars from y = 0 over [edges[k], edges[k+1]] of height heights[k].
  void Bars(const std::vector<double>& edges, const std::vector<double>& heights,
            const cv::Scalar& colour) const;
  // Text vertically centred on a data point, moved by `pixel_offset` (x right, y down).
  void Text(double x, double y, const std::string& text, const cv::Scalar& colour,
            TextAnchor anchor = TextAnchor::kLeft, cv::Point2d pixel_offset = {0, 0}) const;

  double font_scale() const { return font_scale_; }
  cv::Rect plot_area() const { return plot_; }

 private:
  cv::Mat image_;  // the whole image (drawing is clipped to plot_ for data)
  cv::Rect area_;  // the panel
  cv::Rect plot_;  // the plot area inside the panel
  double font_scale_;
  double x_min_ = 0.0, x_max_ = 1.0, y_min_ = 0.0, y_max_ = 1.0;
};

}  // namespace silnet::aggregator
