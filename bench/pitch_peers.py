#!/usr/bin/python3
"""Pitch trackers side by side on fluidsynth-rendered music with known truth.

usage: pitch_peers.py BUILD_DIR [NOTES] [RUNS]
Renders the benchmark music (BUILD_DIR/bin/render_test_music: cello, violin,
viola, contrabass from the FluidR3 soundfont; NOTES notes each), then runs on
every file, with the same pitch range and a 10 ms hop:
  arco pitch   --fps 100 (one row per 10 ms, pYIN + HMM)
  Praat        To Pitch (ac), default parameters apart from floor/ceiling
  aubiopitch   -p yinfft -H 441 (buffer 2048, 4096 for the bass)
Accuracy (score_pitch.py): raw pitch accuracy within 50 and 25 cents, voicing
recall and false alarms; each peer's timestamps are shifted by the lag in
[-50, 50] ms that maximises its RPA50 (generous to peers whose frame times
mark the window start). Speed: CPU seconds (user + sys of the child process,
minimum over RUNS runs) minus the same tool's CPU seconds on a 0.5 s file
(start-up, loading), as times real time on one core.
Prints a markdown table.
"""
import os
import resource
import subprocess
import sys
import wave

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


def shifted(path, shift_s, out_path):
    with open(path) as f, open(out_path, 'w') as g:
        for line in f:
            parts = line.replace(',', ' ').split()
            try:
                g.write('%.4f %s\n' % (float(parts[0]) + shift_s, parts[1]))
            except (ValueError, IndexError):
                pass


def score(truth, track, fmt):
    out = subprocess.run(['/usr/bin/python3', os.path.join(HERE, 'score_pitch.py'), truth, track,
                          '--format', fmt], check=True, capture_output=True, text=True).stdout
    return [float(x) for x in out.split()]


def best_shift_score(truth, track, work):
    best = None
    for ms in range(-50, 51, 5):
        tmp = os.path.join(work, 'shifted.txt')
        shifted(track, ms / 1000.0, tmp)
        s = score(truth, tmp, 'pairs')
        if best is None or s[0] > best[1][0]:
            best = (ms, s)
    return best


def duration_s(wav):
    with wave.open(wav) as w:
        return w.getnframes() / w.getframerate()


def main():
    build = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else 'build')
    notes = sys.argv[2] if len(sys.argv) > 2 else '60'
    runs = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    work = os.path.join(build, 'pitch_peers')
    os.makedirs(work, exist_ok=True)
    with open(os.path.join(work, 'pitch.praat'), 'w') as f:
        f.write(PRAAT_SCRIPT)
    subprocess.run([os.path.join(build, 'bin', 'render_test_music'), work, notes], check=True,
                   stdout=subprocess.DEVNULL)
    # A 0.5 s file measures each tool's start-up cost.
    short = os.path.join(work, 'short.wav')
    with wave.open(os.path.join(work, 'cello.wav')) as w, wave.open(short, 'w') as s:
        s.setparams(w.getparams())
        s.writeframes(w.readframes(w.getframerate() // 2))
    print('| instrument | tool | RPA 50 c | RPA 25 c | voicing recall | voicing false alarms '
          '| time shift (ms) | speed (x real time, 1 core) |')
    print('|---|---|---|---|---|---|---|---|')
    for instrument in ['cello', 'violin', 'viola', 'bass']:
        wav = os.path.join(work, instrument + '.wav')
        truth = os.path.join(work, instrument + '_truth.csv')
        seconds = duration_s(wav)
        for tool in ['arco', 'praat', 'aubio']:
            out = os.path.join(work, '%s.%s.txt' % (instrument, tool))
            cpu = min(cpu_of(commands(tool, build, instrument, wav, out, work)) for _ in range(runs))
            startup = min(cpu_of(commands(tool, build, instrument, short, out + '.short', work))
                          for _ in range(runs))
            if tool == 'arco':
                shift, s = 0, score(truth, out, 'arco')
            else:
                shift, s = best_shift_score(truth, out, work)
            net = max(cpu - startup, 1e-3)
            print('| %s | %s | %.3f | %.3f | %.3f | %.3f | %+d | %.0f |' %
                  (instrument, tool, s[0], s[1], s[2], s[3], shift, seconds / net))
            sys.stdout.flush()


if __name__ == '__main__':
    main()
