#pragma once
/// \file interrupted_writes.h
/// What a signal that ends the process does to the files focal is writing. Every file focal
/// writes goes first to a temporary file beside its target, renamed over the target once
/// complete (so a failed or killed write never leaves a partial target). Without a handler, a
/// process killed by SIGINT or SIGTERM while writing leaves that temporary file behind
/// (`.<name>.tmp-<hex>`); with the handlers installed here it is removed first.

namespace focal {

/// Installs handlers for SIGINT, SIGTERM and SIGHUP that remove the temporary files of the
/// writes in progress, then end the process by the same signal (the default action re-raised,
/// so that the exit status says which signal ended it). A signal whose disposition is not the
/// default (ignored, or a handler of the caller's, such as Python's SIGINT) is left alone.
/// Call once, early, from a program's main thread (the focal command does, and importing the
/// Python module focal does: there SIGTERM and SIGHUP, SIGINT being Python's); safe to call
/// again.
/// The handler is async-signal-safe: it only reads a fixed table of paths and calls unlink().
void remove_temporary_files_on_signals();

}  // namespace focal
