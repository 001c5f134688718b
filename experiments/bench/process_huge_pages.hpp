#pragma once
/// Transparent huge pages for the command's large arrays.
///
/// Why: the command's large arrays (an 11.4 M-hex output is about 0.6 GB of cells and points,
/// its check as much again) are written into fresh memory, one 4 KiB page fault each. On the
/// virtual 2-core machine we measure on, those faults dominate: writing 642 MB into fresh pages
/// took 2.16 s with 4 KiB pages and 0.07 s with 2 MiB pages (bench_refiners' floor, 2026-11-25).
/// Where the kernel gives huge pages only to ranges that ask for them
/// (/sys/kernel/mm/transparent_hugepage/enabled = "madvise", Debian's default), glibc's malloc
/// asks for them on its own large chunks when started with the tunable glibc.malloc.hugetlb=1
/// (glibc >= 2.35). Tunables are read once at process start, so the command sets it and
/// re-executes itself, once, before doing anything else. Output does not depend on it.
///
/// It does nothing when the environment variable HEXREFINE_HUGE_PAGES is "0", when the user set
/// glibc.malloc.hugetlb themselves, when the kernel's mode is "always" (nothing to ask for) or
/// "never" (nothing to get), under AddressSanitizer (its own allocator) or under Valgrind (the
/// re-executed process would leave the tool).

#include <optional>
#include <string>

namespace hexrefine {

/// The transparent-huge-page mode the kernel reports: the bracketed word of `enabled`, e.g.
/// "madvise" from "always [madvise] never"; empty when there is none.
std::string huge_pages_mode(const std::string& enabled);

/// This kernel's mode: huge_pages_mode of /sys/kernel/mm/transparent_hugepage/enabled (empty
/// where the file is missing).
std::string huge_pages_kernel_mode();

/// The GLIBC_TUNABLES value to re-execute with, given the current one (null: unset): the current
/// tunables followed by glibc.malloc.hugetlb=1, or nothing when glibc.malloc.hugetlb is already set
/// (by the user, or by this process' parent: the re-executed process never re-executes again).
std::optional<std::string> huge_pages_tunables(const char* current);

/// Re-executes this process (/proc/self/exe, the same argv and environment plus the tunable)
/// when that gives it huge pages; returns only when it does not (or when exec fails: the command
/// then runs with 4 KiB pages, as before).
void process_prefer_huge_pages(char** argv);

/// Whether this process' large allocations get huge pages: the kernel's mode is "always", or it is
/// "madvise" and the tunable is set (by process_prefer_huge_pages or the user). Recorded in the
/// reports beside the timings, which it changes.
bool process_uses_huge_pages();

}  // namespace hexrefine
