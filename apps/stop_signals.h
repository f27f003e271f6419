#pragma once
// SIGINT, SIGTERM and SIGHUP: the first one during a render (or an export, or `nimbus view`)
// stops it before its next pixel (exit 128 + the signal's number; nothing is written, or with
// checkpoints the checkpoint and the image so far); during writing, or a second one, removes
// every temporary file and ends the process by the signal at once.

// Installs the handlers.
void catch_stop_signals();
// The signal that came, 0 if none.
int stop_signal();
// While true, outputs are being written: a signal ends the process at once.
void set_writing(bool writing);
// "SIGINT", "SIGTERM", "SIGHUP", or "a signal".
const char* signal_name(int sig);
