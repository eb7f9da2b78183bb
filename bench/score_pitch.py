#!/usr/bin/python3
"""Scores a pitch track against the truth CSV written by render_test_music.

usage: score_pitch.py TRUTH_CSV TRACK [--format arco|pairs]
  arco : pitch.csv from `arco pitch` (frame,time_s,f0_hz,confidence,voiced)
  pairs: whitespace- or comma-separated "time_s f0_hz" lines (Praat, aubio);
         f0 <= 0 or NaN means unvoiced.
Each scored truth row (voicing 1 or 0) takes the track frame nearest in time.
Prints: rpa50 rpa25 voicing_recall voicing_false_alarm voiced_rows unvoiced_rows
RPA (raw pitch accuracy) counts voiced truth rows whose estimate is voiced and
within 50 / 25 cents; recall = voiced truth rows estimated voiced; false alarm
= unvoiced truth rows estimated voiced.
"""
import bisect
import math
import sys


def read_track(path, fmt):
    times, f0s = [], []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if not line or line[0].isalpha() or line.startswith('#'):
                continue
            parts = line.replace(',', ' ').split()
            try:
                if fmt == 'arco':
                    t, f0, voiced = float(parts[1]), float(parts[2]), int(parts[4])
                    f0 = f0 if voiced else 0.0
                else:
                    t = float(parts[0])
                    f0 = float(parts[1]) if parts[1] not in ('--undefined--', 'nan') else 0.0
            except (ValueError, IndexError):
                continue
            if math.isnan(f0):
                f0 = 0.0
            times.append(t)
            f0s.append(f0)
    return times, f0s


def read_truth(path):
    """Scored rows (time_s, f0_hz, code) of a truth CSV; code 1 voiced, 0 unvoiced."""
    rows = []
    with open(path) as f:
        next(f)
        for line in f:
            t, f0, code = line.strip().split(',')
            if int(code) >= 0:
                rows.append((float(t), float(f0), int(code)))
    return rows


def counts(truth, times, f0s, shift_s=0.0):
    """[hit50, hit25, recalled, voiced, false_alarms, unvoiced] of a track whose
    timestamps are shifted by shift_s."""
    c = [0] * 6
    if not times:
        return c
    for t, f0, code in truth:
        t -= shift_s  # track time + shift = truth time
        i = bisect.bisect_left(times, t)
        if i > 0 and (i == len(times) or t - times[i - 1] <= times[i] - t):
            i -= 1
        est = f0s[i]
        if code == 0:
            c[5] += 1
            c[4] += est > 0
            continue
        c[3] += 1
        if est > 0:
            c[2] += 1
            cents = abs(1200 * math.log2(est / f0))
            c[0] += cents <= 50
            c[1] += cents <= 25
    return c


def main():
    truth_path, track_path = sys.argv[1], sys.argv[2]
    fmt = sys.argv[4] if len(sys.argv) > 4 and sys.argv[3] == '--format' else 'arco'
    times, f0s = read_track(track_path, fmt)
    if not times:
        print('0 0 0 0 0 0')
        return
    hit50, hit25, recalled, voiced, false_alarms, unvoiced = counts(read_truth(truth_path), times,
                                                                    f0s)
    print('%.4f %.4f %.4f %.4f %d %d' % (hit50 / max(voiced, 1), hit25 / max(voiced, 1),
                                         recalled / max(voiced, 1),
                                         false_alarms / max(unvoiced, 1), voiced, unvoiced))


if __name__ == '__main__':
    main()
