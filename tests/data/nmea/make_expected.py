#!/usr/bin/env python3
"""Extracts, from a gpsd regression .chk file, the fix values gpsd decoded for each GGA and RMC sentence.

The .chk file echoes every input sentence, each followed by the JSON gpsd reported after it. For every TPV
object with a time, the sentence it belongs to is the latest GGA (and the latest RMC) before it whose UTC time
of day equals the TPV's time; its ordinal among the log's GGA (RMC) sentences identifies it. One output line
per such sentence, from the first TPV that belongs to it (later ones may carry changes other sentences made,
e.g. a GSA that drops the mode):
  GGA <ordinal> <time> <mode> <status> <lat> <lon> <altHAE> <altMSL>
  RMC <ordinal> <time> <mode> <status> <lat> <lon>
'-' where gpsd printed no value (status below 2, position when mode < 2, ...). Values as gpsd printed them.
Usage: make_expected.py LOG.chk > LOG.expected   (run from anywhere; only the .chk is read)
"""
import json
import sys


def tod(t):  # "hhmmss.ss" or TPV "YYYY-MM-DDThh:mm:ss.sssZ" -> seconds of the day
    if 'T' in t:
        h, m, s = t[11:-1].split(':')
    else:
        h, m, s = t[0:2], t[2:4], t[4:]
    return int(h) * 3600 + int(m) * 60 + float(s)


def main(path):
    count = {'GGA': 0, 'RMC': 0}
    last = {}
    seen = {}
    for line in open(path, errors='replace'):
        line = line.rstrip('\r\n')
        if line.startswith('$'):
            fields = line[1:line.rfind('*')].split(',')
            kind = fields[0][-3:]
            if kind in count:
                last[kind] = (count[kind], fields[1])
                count[kind] += 1
            continue
        if not line.startswith('{'):
            continue
        o = json.loads(line)
        if o.get('class') != 'TPV' or 'time' not in o:
            continue
        for kind in ('GGA', 'RMC'):
            if kind not in last or not last[kind][1] or abs(tod(last[kind][1]) - tod(o['time'])) > 1e-6:
                continue
            # status is printed by gpsd only when it is DGPS (2) or better
            v = lambda k: repr(o[k]) if k in o else '-'
            out = [kind, str(last[kind][0]), o['time'], str(o['mode']), v('status'), v('lat'), v('lon')]
            if kind == 'GGA':
                out += [v('altHAE'), v('altMSL')]
            seen.setdefault((kind, last[kind][0]), ' '.join(out))
    print('# gpsd TPV values by sentence, from ' + path.split('/')[-1] + ' (see tests/data/PROVENANCE.txt)')
    for text in seen.values():
        print(text)


main(sys.argv[1])
