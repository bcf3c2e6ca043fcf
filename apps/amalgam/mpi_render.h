#pragma once
/// \file Image-parallel renders over MPI (docs/mpi.md): `mpirun -np N amalgam render ...`.
///
/// Every rank loads the scene itself. Rank 0 cuts the image into tiles and, for each round of
/// samples, hands them out one at a time to whichever rank asks (a queue: a slow rank takes
/// fewer), renders tiles itself on a thread of its own, and pastes the results into its film.
/// A tile carries its pixels' running sums (render_tile, render/render.h), so every pixel adds
/// its samples in sample order whoever renders it: the film, and so the image, the cost image
/// and the counters, are the bytes of a single-process render for any N. A round completes
/// before the next begins, so rank 0's film is always a whole number of samples per pixel: the
/// checkpoints and interrupted outputs of a single-process render, resumable with any N.
///
/// Built only with AMALGAM_HAVE_MPI; a process not started by mpirun (no launcher variables in
/// its environment) never initialises MPI and renders exactly as without this file.

#include <atomic>
#include <exception>
#include <functional>
#include <string>
#include <vector>

#include "amalgam/render/render.h"

namespace amalgam::cli::mpi {

/// MPI for the life of `main`: MPI_Init when the process was started by an MPI launcher
/// (mpirun, srun), MPI_Finalize at the end. Otherwise nothing.
class Session {
 public:
  Session(int* argc, char*** argv);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
};

/// Whether this process is one of several ranks (MPI started and more than one rank).
bool parallel();
int rank();
int size();

/// Every rank calls this once its own preparation is done, with the exception it failed with
/// (or none). When no rank failed, returns 0. Else the failing ranks' exceptions are rethrown
/// (on rank r > 0 with "rank r on HOST: " before the message) and the other ranks return the
/// worst exit status (rank 0 after saying that another rank failed).
int agree(std::exception_ptr failure);

/// Rank 0 sends `text` to every rank; returns rank 0's text on every rank.
std::string broadcast(const std::string& text);

/// Renders samples s0 .. s1 - 1 into a tile (Tracer::render_tile, render/tracer.h); false when
/// `cancel` stopped it.
using TileRenderer =
    std::function<bool(FilmTile& tile, int s0, int s1, const std::atomic<bool>* cancel)>;

/// Why a parallel render stopped early (rank 0).
struct Stop {
  int signal = 0;       ///< the signal that stopped it (SIGINT, SIGTERM, SIGHUP or SIGQUIT)
  int signal_rank = 0;  ///< the rank that received it
  std::string missing;  ///< the tiles of the unfinished round not returned, and their holders
};

/// Rank 0: renders `options` as render() does (resume, control), with the ranks' help, in
/// rounds of samples that double while one lasts less than half of `round_seconds` (0: rounds
/// of a single process's pass); control.on_pass is called after each. A rank silent for
/// `timeout` seconds with a tile is taken as lost (said on stderr) and its tile is rendered by
/// the others. `signal` is the signal this process received (0: none). Sets `stop` when
/// interrupted.
RenderOutput render_root(const TileRenderer& render_tile, const RenderOptions& options,
                         FilmState* resume, const RenderControl& control,
                         const std::atomic<int>& signal, double timeout, double round_seconds,
                         Stop& stop);

/// Ranks > 0: renders the tiles rank 0 hands out until it says stop. `cancel` (this process's
/// SIGINT, SIGTERM, SIGHUP, SIGQUIT) stops the tile under way and tells rank 0, which stops every
/// rank.
void serve(const TileRenderer& render_tile, const RenderOptions& options,
           const std::atomic<bool>& cancel, const std::atomic<int>& signal);

/// Rank 0, once its outputs are written: tells every rank to stop (waiting for tiles still
/// under way). Returns false, after saying which, when a rank was lost (the caller then ends
/// the job with abort()).
bool release();

/// Runs jobs 0 .. n - 1 spread over the ranks (`amalgam experiment` under mpirun): rank 0 hands
/// them out one at a time from a queue and runs its own share on a thread of its own. On rank 0,
/// calls `done(i, output of job i)` for every job in order 0 .. n - 1 as soon as the jobs up to i
/// are finished; other ranks return once every job is done. A job that throws fails the run:
/// its message, with the rank, is thrown again on rank 0 (RuntimeError) after every rank stops.
void spread(int n, const std::function<std::string(int)>& job,
            const std::function<void(int, const std::string&)>& done);

/// Ends every rank of the job now (MPI_Abort) with `status`.
[[noreturn]] void abort(int status);

}  // namespace amalgam::cli::mpi
