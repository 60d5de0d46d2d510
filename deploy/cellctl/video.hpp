#pragma once
// The virtual assembly as an MP4 (H.264), the paper's feedback to the designer: the report's
// 3D view rendered frame by frame in headless chromium (report.js, #video=FPS), each frame
// captioned with its step and that step's findings, encoded by ffmpeg. Needs chromium and
// ffmpeg on the PATH (deploy/install-deps.sh installs them; AGILE_CELL_CHROMIUM names
// another browser).

#include <filesystem>
#include <string>

namespace cellctl {

struct VideoFacts {
  int frames = 0;
  double seconds = 0;
};

// `report_html`: the page twin::html_report made. Throws std::runtime_error with what went
// wrong (a program missing, no frame rendered, ffmpeg's complaint).
VideoFacts write_video(const std::string& report_html, const std::filesystem::path& file, int fps = 25);

}  // namespace cellctl
