// Log lines straight to the systemd journal when systemd has connected standard error to
// it (a service's JOURNAL_STREAM): each with its level as PRIORITY= and where it comes
// from as TILTH_NODE= (a node such as chain/estimate, or run, status, runtime), so that
// `journalctl -u tilth@seeder -p warning` and `journalctl TILTH_NODE=chain/estimate`
// select them.
#pragma once

namespace tilth::cli {

// True when standard error is the journal stream systemd gave this process.
bool stderr_is_journal();

// Sends every log line to the journal from now on; a line the journal does not take goes
// to standard error as before.
void log_to_journal();

}  // namespace tilth::cli
