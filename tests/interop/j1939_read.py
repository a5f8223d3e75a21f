#!/usr/bin/env python3
"""Reads a candump log with python-can (Debian's python3-can) and prints what a J1939 tool sees in it, decoded
here from the standards' layouts, not with fieldguard's code: the first frame, every Address Claimed (NAME
fields) and every DM1 (lamps, SPN/FMI/occurrences), reassembling BAM transfers.

    j1939_read.py LOG
    first 18EEFF80 extended
    claim 80 name=A000FF0000000000 identity=0 manufacturer=0 function=255 industry_group=2 arbitrary=1
    dm1 1700000000123456 lamps=04 dtcs=520194/2/1
"""
import sys

import can  # python-can


def pgn_of(arbitration_id):
    pf = (arbitration_id >> 16) & 0xFF
    pgn = (arbitration_id >> 8) & 0x3FFFF
    return pgn & 0x3FF00 if pf < 240 else pgn


def dm1_line(us, data):
    dtcs = []
    for at in range(2, len(data) - 3, 4):
        d = data[at:at + 4]
        if bytes(d) == b"\xff\xff\xff\xff":
            break
        spn = d[0] | d[1] << 8 | (d[2] >> 5) << 16
        fmi = d[2] & 0x1F
        occurrences = d[3] & 0x7F
        if spn or fmi or occurrences:
            dtcs.append(f"{spn}/{fmi}/{occurrences}")
    return f"dm1 {us} lamps={data[0]:02X} dtcs={','.join(dtcs) or '-'}"


def main(path):
    bam = {}  # source address -> [pgn, size, packets, data]
    first = True
    for msg in can.LogReader(path):
        arbitration_id = msg.arbitration_id
        data = bytes(msg.data)
        us = round(msg.timestamp * 1e6)
        if first:
            print(f"first {arbitration_id:08X} {'extended' if msg.is_extended_id else 'standard'}")
            first = False
        pgn = pgn_of(arbitration_id)
        source = arbitration_id & 0xFF
        if pgn == 0xEE00 and len(data) == 8:
            name = int.from_bytes(data, "little")
            print(f"claim {source:02X} name={name:016X} identity={name & 0x1FFFFF} "
                  f"manufacturer={(name >> 21) & 0x7FF} function={(name >> 40) & 0xFF} "
                  f"industry_group={(name >> 60) & 7} arbitrary={name >> 63}")
        elif pgn == 0xFECA:
            print(dm1_line(us, data))
        elif pgn == 0xEC00 and data[0] == 0x20:  # TP.CM BAM
            bam[source] = [data[5] | data[6] << 8 | data[7] << 16, data[1] | data[2] << 8, data[3], b""]
        elif pgn == 0xEB00 and source in bam:
            transfer = bam[source]
            transfer[3] += data[1:8]
            if data[0] == transfer[2]:
                del bam[source]
                if transfer[0] == 0xFECA:
                    print(dm1_line(us, transfer[3][:transfer[1]]))


if __name__ == "__main__":
    main(sys.argv[1])
