#!/usr/bin/python3
"""Pitch trackers side by side on fluidsynth-rendered music with known truth.

usage: pitch_peers.py BUILD_DIR [NOTES] [RUNS] [SEEDS]
Renders the benchmark music (BUILD_DIR/bin/render_test_music: cello, violin,
viola, contrabass from the FluidR3 soundfont; NOTES notes each) once per seed
(SEEDS: comma-separated, default 11 to 18), then runs on every file, with the
same pitch range and a 10 ms hop:
  arco pitch   --fps 100 (one row per 10 ms, pYIN + HMM)
  Praat        To Pitch (ac), default parameters apart from floor/ceiling
  aubiopitch   -p yinfft -H 441 (buffer 2048, 4096 for the bass)
Accuracy (score_pitch.py), pooled over the seeds, against two truths on the
same frames: the MIDI score (INSTRUMENT_truth.csv) and the score corrected by
each key's measured sound (INSTRUMENT_truth_sound.csv, sound_truth.h). Raw
pitch accuracy within 50 and 25 cents, voicing recall and false alarms; each
peer's timestamps are shifted by the lag in [-50, 50] ms (5 ms steps) that
maximises its pooled RPA50 against that truth (generous to peers whose frame
times mark the window start; arco's are used as they are). Speed, on the
first seed: CPU seconds (user + sys of the child process, minimum over RUNS
runs) minus the same tool's CPU seconds on a 0.5 s file (start-up, loading),
as times real time on one core.
Prints two markdown tables.
"""
import os
import resource
import subprocess
import sys
import wave

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from score_pitch import counts, read_track, read_truth  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
RANGES = {'cello': (60, 2000), 'violin': (180, 4200), 'viola': (120, 2800), 'bass': (38, 1200)}

PRAAT_SCRIPT = '''form args
  sentence input
  sentence output
  real floor
  real ceiling
endform
s = Read from file: input$
p = To Pitch (ac): 0.01, floor, 15, "no", 0.03, 0.45, 0.01, 0.35, 0.14, ceiling
n = Get number of frames
out$ = ""
for i to n
  t = Get time from frame number: i
  f = Get value in frame: i, "Hertz"
  if f = undefined
    f = 0
  endif
  out$ = out$ + fixed$(t, 4) + " " + fixed$(f, 3) + newline$
endfor
writeFile: output$, out$
'''


def cpu_of(cmd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def commands(tool, build, instrument, wav, out, work):
    lo, hi = RANGES[instrument]
    if tool == 'arco':
        return [os.path.join(build, 'bin', 'arco'), 'pitch', wav, '--instrument', instrument,
                '--fps', '100', '-o', out]
    if tool == 'praat':
        return ['praat', '--run', os.path.join(work, 'pitch.praat'), wav, out, str(lo), str(hi)]
    buf = '4096' if instrument == 'bass' else '2048'
    return ['sh', '-c', 'aubiopitch -i "%s" -p yinfft -B %s -H 441 -u Hz > "%s"' % (wav, buf, out)]


def best_shift(truths, tracks, shifts):
    """(shift_ms, pooled counts) maximising pooled hits within 50 cents (ties: 25 cents)."""
    best = None
    for ms in shifts:
        total = [0] * 6
        for truth, (times, f0s) in zip(truths, tracks):
            total = [x + y for x, y in zip(total, counts(truth, times, f0s, ms / 1000.0))]
        if best is None or total[:2] > best[1][:2]:
            best = (ms, total)
    return best


def duration_s(wav):
    with wave.open(wav) as w:
        return w.getnframes() / w.getframerate()


def main():
    build = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else 'build')
    notes = sys.argv[2] if len(sys.argv) > 2 else '60'
    runs = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    seeds = (sys.argv[4] if len(sys.argv) > 4 else '11,12,13,14,15,16,17,18').split(',')
    root = os.path.join(build, 'pitch_peers')
    os.makedirs(root, exist_ok=True)
    with open(os.path.join(root, 'pitch.praat'), 'w') as f:
        f.write(PRAAT_SCRIPT)
    works = []
    for seed in seeds:
        work = os.path.join(root, 'seed' + seed)
        os.makedirs(work, exist_ok=True)
        subprocess.run([os.path.join(build, 'bin', 'render_test_music'), work, notes, seed],
                       check=True, stdout=subprocess.DEVNULL)
        works.append(work)
    # A 0.5 s file measures each tool's start-up cost.
    short = os.path.join(root, 'short.wav')
    with wave.open(os.path.join(works[0], 'cello.wav')) as w, wave.open(short, 'w') as s:
        s.setparams(w.getparams())
        s.writeframes(w.readframes(w.getframerate() // 2))
    rows = {'score': [], 'sound': []}
    for instrument in ['cello', 'violin', 'viola', 'bass']:
        for tool in ['arco', 'praat', 'aubio']:
            tracks = []
            for k, work in enumerate(works):
                wav = os.path.join(work, instrument + '.wav')
                out = os.path.join(work, '%s.%s.txt' % (instrument, tool))
                cmd = commands(tool, build, instrument, wav, out, root)
                if k == 0:
                    cpu = min(cpu_of(cmd) for _ in range(runs))
                    startup = min(cpu_of(commands(tool, build, instrument, short, out + '.short',
                                                  root)) for _ in range(runs))
                    speed = duration_s(wav) / max(cpu - startup, 1e-3)
                else:
                    cpu_of(cmd)
                tracks.append(read_track(out, 'arco' if tool == 'arco' else 'pairs'))
            for kind, suffix in [('score', '_truth.csv'), ('sound', '_truth_sound.csv')]:
                truths = [read_truth(os.path.join(w, instrument + suffix)) for w in works]
                shift, c = best_shift(truths, tracks, [0] if tool == 'arco' else
                                      range(-50, 51, 5))
                hit50, hit25, recalled, voiced, false_alarms, unvoiced = c
                rows[kind].append('| %s | %s | %.4f | %.4f | %d / %d of %d | %.3f | %.3f | %+d |%s' % (
                    instrument, tool, hit50 / voiced, hit25 / voiced, voiced - hit50,
                    voiced - hit25, voiced, recalled / voiced, false_alarms / max(unvoiced, 1), shift,
                    ' %.0f |' % speed if kind == 'score' else ''))
    for kind, title in [('score', 'truth = MIDI score'),
                        ('sound', 'truth = score corrected by each key\'s measured sound')]:
        print('\n%s (seeds %s, pooled)\n' % (title, ','.join(seeds)))
        print('| instrument | tool | RPA 50 c | RPA 25 c | misses 50 / 25 c of voiced | voicing recall '
              '| voicing false alarms | time shift (ms) |%s' %
              (' speed (x real time, 1 core) |' if kind == 'score' else ''))
        print('|---|---|---|---|---|---|---|---|%s' % ('---|' if kind == 'score' else ''))
        print('\n'.join(rows[kind]))


if __name__ == '__main__':
    main()
