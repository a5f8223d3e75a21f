#!/usr/bin/env python3
"""Condenses einride/xsens-go golden decodes (testdata/N/output.golden) into one line per message.

Keeps the first FIRST messages of each set, plus the first message that carries a data type not seen yet in
that set (GNSSPVTData, GNSSSatInfo, ...). Line: "<set> <message index> Name=v1,v2,..." with the golden's own
names and numbers, verbatim ("X:", "Q0:", "Lat:" labels dropped; GNSSPVTData and GNSSSatInfo keep "Key:value").
Usage: make_expected.py GOLDEN_ROOT > einride_expected.txt   (GOLDEN_ROOT holds 1/ .. 5/)
"""
import sys

FIRST = 12
KEEP_LABELS = ('GNSSPVTData', 'GNSSSatInfo')


def messages(path):
    for block in open(path).read().strip().split('\n\n'):
        fields, name = [], None
        for line in block.split('\n'):
            if not line.startswith('  '):
                name = line.rstrip(':')
                fields.append([name, []])
            elif name.startswith(KEEP_LABELS) or ':' not in line or line.strip()[0].isdigit():
                fields[-1][1].append(line.strip())
            else:
                fields[-1][1].append(line.strip().split(':', 1)[1])
        yield fields


def main(root):
    print('# set index Name=values...  (einride/xsens-go testdata/<set>/output.golden; see tests/data/PROVENANCE.txt)')
    for s in '12345':
        seen = set()
        for i, fields in enumerate(messages(f'{root}/{s}/output.golden')):
            names = {n for n, _ in fields}
            if i < FIRST or not names <= seen:
                print(s, i, ' '.join(n + '=' + ','.join(v) for n, v in fields))
            seen |= names


main(sys.argv[1])
