#include "lidarloop/io/plot.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "lidarloop/io/detail/binary_io.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::io {
namespace {

// gnuplot strings are single-quoted; a quote inside is doubled.
std::string Quote(const std::string& text) {
    std::string quoted = "'";
    for (char c : text) quoted += c == '\'' ? std::string("''") : std::string(1, c);
    return quoted + "'";
}

const char* StyleName(PlotSeries::Style style) {
    switch (style) {
        case PlotSeries::Style::kLines:
            return "lines lw 2";
        case PlotSeries::Style::kSteps:
            return "steps lw 2";
        case PlotSeries::Style::kPoints:
            return "points pt 7 ps 0.6";
        case PlotSeries::Style::kBoxes:
            return "boxes fs solid 0.35 noborder";
    }
    return "lines";
}

void WriteRange(std::ostringstream& script, const char* axis, double min, double max) {
    if (min < max) script << "set " << axis << "range [" << min << ":" << max << "]\n";
}

bool HasPoints(const PlotSeries& series) { return !series.x.empty() && !series.y.empty(); }

// gnuplot fails on a data block without points, and on a plot with nothing to autoscale on
// (a results file that never detects anything leaves such curves): plot only the series with
// points, and give an empty plot fixed ranges and a note instead.
void WritePlotCommand(std::ostringstream& script, const Plot& plot) {
    if (std::none_of(plot.series.begin(), plot.series.end(), HasPoints)) {
        if (!(plot.x_min < plot.x_max))
            script << (plot.x_log ? "set xrange [1:10]\n" : "set xrange [0:1]\n");
        if (!(plot.y_min < plot.y_max)) script << "set yrange [0:1]\n";
        script << "set label 1 'no data' at graph 0.5, graph 0.5 center\nplot NaN notitle\n";
        return;
    }
    const char* separator = "plot ";
    for (std::size_t s = 0; s < plot.series.size(); ++s) {
        if (!HasPoints(plot.series[s])) continue;
        script << separator << "$data" << s << " using 1:2 with "
               << StyleName(plot.series[s].style);
        if (s < plot.colors.size() && !plot.colors[s].empty())
            script << " lc rgb " << Quote(plot.colors[s]);
        script << " title " << Quote(plot.series[s].title);
        separator = ", ";
    }
    script << "\n";
}

}  // namespace

bool GnuplotAvailable() { return std::system("gnuplot --version > /dev/null 2>&1") == 0; }

std::string GnuplotScript(const std::filesystem::path& png, const Plot& plot) {
    std::ostringstream script;
    script.precision(10);
    for (std::size_t s = 0; s < plot.series.size(); ++s) {
        script << "$data" << s << " << EOD\n";
        const PlotSeries& series = plot.series[s];
        for (std::size_t i = 0; i < std::min(series.x.size(), series.y.size()); ++i) {
            script << series.x[i] << ' ' << series.y[i] << '\n';
        }
        script << "EOD\n";
    }
    script << "set terminal pngcairo size 1000,700 enhanced font 'sans,12'\n"
           << "set output " << Quote(png.string()) << "\n"
           << "set title " << Quote(plot.title) << " noenhanced\n"
           << "set xlabel " << Quote(plot.x_label) << " noenhanced\n"
           << "set ylabel " << Quote(plot.y_label) << " noenhanced\n"
           << "set grid\nset key outside right top noenhanced\n";
    if (plot.x_log) script << "set logscale x\n";
    if (plot.equal_axes) script << "set size ratio -1\nset key below\n";
    WriteRange(script, "x", plot.x_min, plot.x_max);
    WriteRange(script, "y", plot.y_min, plot.y_max);
    for (double x : plot.vertical_lines) {
        script << "set arrow from " << x << ", graph 0 to " << x
               << ", graph 1 nohead dt 2 lc rgb 'black'\n";
    }
    WritePlotCommand(script, plot);
    return script.str();
}

namespace {

struct GnuplotRun {
    bool not_installed = false;
    int status = 0;      // as waitpid gives it
    std::string output;  // stdout and stderr
};

// Runs `gnuplot SCRIPT` without a shell: the path is an argument, never shell text, so no
// character in a user's folder name (a quote, a semicolon) can run a command.
GnuplotRun RunGnuplot(const std::filesystem::path& png, const std::filesystem::path& script_file) {
    // Close-on-exec: a gnuplot started by another thread meanwhile must not hold this pipe open
    // (the read below would wait for it); the child's dup2 copies are not close-on-exec.
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0) throw WriteError(png, "cannot run gnuplot (no pipe)");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, fds[1], STDERR_FILENO);
    // Absolute, so that a path starting with '-' is not read as an option.
    std::string program = "gnuplot";
    std::string script = std::filesystem::absolute(script_file).string();
    char* const argv[] = {program.data(), script.data(), nullptr};
    pid_t pid = 0;
    const int spawned = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv, environ);
    posix_spawn_file_actions_destroy(&actions);
    close(fds[1]);
    GnuplotRun run;
    if (spawned != 0) {
        close(fds[0]);
        if (spawned == ENOENT) {
            run.not_installed = true;
            return run;
        }
        throw WriteError(png, "cannot run gnuplot");
    }
    char buffer[256];
    for (ssize_t n; (n = read(fds[0], buffer, sizeof(buffer))) != 0;) {
        if (n > 0) {
            run.output.append(buffer, static_cast<std::size_t>(n));
        } else if (errno != EINTR) {
            break;
        }
    }
    close(fds[0]);
    while (waitpid(pid, &run.status, 0) < 0) {
        if (errno != EINTR) throw WriteError(png, "cannot wait for gnuplot");
    }
    return run;
}

}  // namespace

void RenderPlot(const std::filesystem::path& png, const Plot& plot) {
    const std::string script = GnuplotScript(png, plot);
    std::filesystem::path script_file = png;
    script_file.replace_extension(".gp");
    detail::WriteWholeFile(script_file, script);
    const GnuplotRun run = RunGnuplot(png, script_file);
    if (run.not_installed) {
        throw WriteError(png, "gnuplot is not installed (apt-get install gnuplot-nox)");
    }
    if (!WIFEXITED(run.status) || WEXITSTATUS(run.status) != 0) {
        throw WriteError(png, "gnuplot failed: " + run.output);
    }
}

}  // namespace lidarloop::io
