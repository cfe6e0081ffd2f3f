// `tilth ab merge SHARD_DIR... --out DIR`: the report of a comparison run as shards
// (`tilth ab --shard I/N`), from the results they left.
#pragma once

namespace tilth::ab {

// argv[1] is "merge". Returns the exit code: 0, 1 (a job failed or is missing, or the
// shards cannot be merged), 2 (a mistake on the command line).
int merge_command(int argc, char** argv);

}  // namespace tilth::ab
