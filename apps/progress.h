#pragma once
// stderr shared by progress bars and warnings. A bar is one line, redrawn: what is being done,
// a bar, the fraction, the time so far and the ETA. Bars and warnings come from several threads
// (the render's, the display server's): one at a time, so that a warning never lands inside a
// bar's line (issue 44).

#include <functional>
#include <string>

// Ends an open bar's line, if one is drawn; a render without a bar (-q, or stderr not a
// terminal) prints no empty lines.
void end_bar_line();
// "nimbus: warning: W" on a line of its own.
void print_warning(const std::string& w);
// Draws `what`'s bar at `fraction` done after `elapsed` seconds, `note` after it.
void print_progress(const char* what, double fraction, double elapsed,
                    const std::string& note = {});
// A progress callback that draws `what`'s bar, timed from when it is made, with note() after it.
std::function<void(double)> progress_bar(const char* what, std::function<std::string()> note = {});
// The objects' compile's bar: drawn only once it has taken half a second (most scenes compile
// faster), on a line of its own.
std::function<void(double)> objects_bar();
