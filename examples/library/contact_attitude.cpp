// contact_attitude CAPTURE: an antenna's attitude from a contact capture through antpose's
// library: read and validate the capture, measure, print the angles with their 1σ.
#include <cstdio>
#include <exception>

#include <antpose/core/error.hpp>
#include <antpose/geometry/rotation.hpp>
#include <antpose/io/capture.hpp>
#include <antpose/measure/contact.hpp>
#include <antpose/version.hpp>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: contact_attitude CAPTURE\n");
    return 2;
  }
  try {
    antpose::Diagnostics diagnostics;
    const antpose::Capture capture = antpose::read_capture(argv[1], diagnostics);
    for (const auto& w : diagnostics.warnings()) std::fprintf(stderr, "warning: %s\n", w.to_string().c_str());
    const antpose::measure::ContactResult r = antpose::measure::measure_contact(capture);
    std::printf("antpose %s\n", antpose::version_string().c_str());
    if (r.azimuth_magnetic)
      std::printf("azimuth (magnetic) %.2f ± %.2f deg\n", antpose::rad2deg(*r.azimuth_magnetic),
                  antpose::rad2deg(r.sigma.azimuth));
    std::printf("downtilt %.2f ± %.2f deg\n", antpose::rad2deg(r.downtilt), antpose::rad2deg(r.sigma.downtilt));
    return 0;
  } catch (const antpose::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 3;
  }
}
