#pragma once
// The process exit codes of every subcommand and tool: 0 success, 2 unusable input or usage error,
// 1 an internal failure (a bug or the machine: out of disk, ...).

namespace fieldguard {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitBadInput = 2;

}  // namespace fieldguard
