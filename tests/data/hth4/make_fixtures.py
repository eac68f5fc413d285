#!/usr/bin/python3
"""Writes the HTH4 test files of this folder, in HeartToHeart4's schema (hth4-files.md §2, §6), by
hand and independently of rcb4's writer: the project three_motions.h4p (HTH4 2.2+ layout), the same
project in the 2.0-2.1 layout (three_motions_2_0.h4p) and a trim file (trims.h4t). The values are
made up; the frames of motion 1 are the ones hth4-files.md §2.6 prints. Run it to regenerate:
    tests/data/hth4/make_fixtures.py
SPDX-License-Identifier: BSL-1.0"""
import os

HERE = os.path.dirname(os.path.abspath(__file__))
XSI = 'xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xmlns:xsd="http://www.w3.org/2001/XMLSchema"'


def frame(*body):
    """A frame with its SIZE byte and SUM (protocol.md §2): SIZE = len + 2, SUM = low byte of the sum."""
    b = [len(body) + 2, *body]
    return b + [sum(b) & 0xFF]


def text(b):
    return " ".join(f"{x:02X}" for x in b)


TAIL = [0x03, 0x0D, 0x10, 0xFF]
RETURN = [0x03, 0x0D, 0x10]


def motions(base):
    """The three motions compiled at slot base @base (0x0B80 or 0x0BB8)."""
    def at(slot, off=0):
        return base + 2048 * slot + off

    def jump(code, target, cond):
        return frame(code, target & 0xFF, (target >> 8) & 0xFF, target >> 16, cond)

    # M001, hth4-files.md §2.6 / §5.7: C1 = 2; a pose on ICS 2/3; C1 - 1, to Pos4 when 0; back to
    # the pose; Pos4 (home); RETURN; the tail.
    m1 = [[0x08, 0x00, 0x02, 0x57, 0x04, 0x00, 0x02, 0x67],
          [0x0D, 0x10, 0x0C, 0x00, 0x00, 0x00, 0x00, 0x14, 0x78, 0x1E, 0x20, 0x1C, 0x0F],
          [0x08, 0x07, 0x02, 0x57, 0x04, 0x00, 0x01, 0x6D],
          jump(0x0B, at(0, 0x2B), 0x05),
          jump(0x0B, at(0, 0x08), 0x00),
          [0x0D, 0x10, 0x0C, 0x00, 0x00, 0x00, 0x00, 0x1E, 0x4C, 0x1D, 0x4C, 0x1D, 0x19],
          RETURN, TAIL]
    # M002: a bow, ICS 2 to 7000 and ICS 3 to 8000 in 30 frames; stretch 80 on both; RETURN.
    m2 = [frame(0x10, 0x0C, 0x00, 0x00, 0x00, 0x00, 0x1E, 0x58, 0x1B, 0x40, 0x1F),
          frame(0x12, 0x0C, 0x00, 0x00, 0x00, 0x00, 0x01, 0x50, 0x50),
          RETURN, TAIL]
    # M003: CALL motion 2, then home in 20 frames.
    m3 = [jump(0x0C, at(1), 0x00),
          frame(0x10, 0x0C, 0x00, 0x00, 0x00, 0x00, 0x14, 0x4C, 0x1D, 0x4C, 0x1D),
          RETURN, TAIL]
    return {0: ("wave_twice", 516, m1), 1: ("bow", 0, m2), 2: ("bow and home", 0, m3)}


SERVOS = {0: ("head", 0), 2: ("left_shoulder", -40), 3: ("right_shoulder", 25), 4: ("left_elbow", 0),
          5: ("right_elbow", 12), 16: ("left_knee", -1980), 17: ("right_knee", 2000)}


def project(base):
    L = ['<?xml version="1.0"?>', f'<Rcb4 {XSI}>']
    config = 0x801B
    L.append(f"  <Config>\n    <unsignedByte>{config & 0xFF}</unsignedByte>\n    <unsignedByte>{config >> 8}</unsignedByte>\n  </Config>")
    adc = [0] * 22
    adc[2], adc[3] = 273 & 0xFF, 273 >> 8  # AD1 = 273
    L.append("  <AdcReference>")
    L += [f"    <unsignedByte>{b}</unsignedByte>" for b in adc]
    L.append("  </AdcReference>")
    L.append("  <Kri3>")
    for k, v in [("Name", "KRI-3"), ("Count", 11), ("RomAddress", 0), ("RamAddress", 844), ("DeviceNumber", 35),
                 ("Code", 1), ("ID", 31), ("ReceiveDataAddress", 0), ("ReceiveDataSize", 7), ("ButtonValue", 0),
                 ("PA1", 0), ("PA2", 0), ("PA3", 0), ("PA4", 0), ("CheckSum", 0)]:
        L.append(f"    <{k}>{v}</{k}>")
    L.append("  </Kri3>")
    L.append("  <MotionDataCollection>")
    ms = motions(base)
    for n in range(120):
        key = f"M{n + 1:03d}"
        name, buttons, frames = ms.get(n, (key, 0, []))
        L.append("    <DictionaryEntry>")
        L.append(f'      <Key xsi:type="xsd:string">{key}</Key>')
        L.append('      <Value xsi:type="Motion">')
        L.append(f"        <Number>{n}</Number>")
        L.append(f"        <Name>{name}</Name>")
        L.append("        <Date>2026-11-25T10:00:00.0000000+01:00</Date>")
        L.append(f"        <ButtonData>{buttons}</ButtonData>")
        L.append("        <CompareType>Equals</CompareType>")
        if frames:
            L.append("        <MotionData>")
            L += [f'          <anyType xsi:type="xsd:string">{text(f)}</anyType>' for f in frames]
            L.append("        </MotionData>")
        else:
            L.append("        <MotionData />")
        L.append(f"        <Address>{base + 2048 * n}</Address>")
        L.append("        <KeyCode>None</KeyCode>")
        L.append("      </Value>")
        L.append("    </DictionaryEntry>")
    L.append("  </MotionDataCollection>")
    L.append("  <ServoConfigParams>")
    for k in range(35):
        name, trim = SERVOS.get(k, (f"servo{k}", 0))
        mode = "Normal" if k in SERVOS else "None"
        L.append("    <DictionaryEntry>")
        L.append(f'      <Key xsi:type="xsd:string">{name}</Key>')
        L.append('      <Value xsi:type="ServoItem">')
        for e, v in [("Name", name), ("Count", 20), ("RomAddress", 1574 + 20 * k), ("RamAddress", 144 + 20 * k),
                     ("Mode", mode), ("Port", "SIO2" if k % 2 else "SIO1"), ("DeviceNumber", k), ("Code", 0),
                     ("ID", k // 2), ("Trim", trim), ("Position", 7500), ("Mixing1Address", 65535),
                     ("Mixing1Rate", 0), ("Mixing2Address", 65535), ("Mixing2Rate", 0), ("DisplayRate", "1")]:
            L.append(f"        <{e}>{v}</{e}>")
        L.append(f"        <Location>\n          <X>{16 + 80 * (k % 6)}</X>\n          <Y>{16 + 40 * (k // 6)}</Y>\n        </Location>")
        L.append("        <Group>0</Group>")
        L.append("        <ForeColor />")
        L.append("        <BackColor />")
        L.append("      </Value>")
        L.append("    </DictionaryEntry>")
    L.append("  </ServoConfigParams>")
    L.append(f"  <StartupMotionAddress>{base}</StartupMotionAddress>")
    L.append("  <LowPowerMotionAddress>-1</LowPowerMotionAddress>")
    L.append("  <LowPowerValue>0</LowPowerValue>")
    L.append("  <PriorityMotionCollection>")
    for key in [str(k) for k in range(13)] + ["-1"]:
        L.append("    <DictionaryEntry>")
        L.append(f'      <Key xsi:type="xsd:int">{key}</Key>')
        if key == "0":
            L.append('      <Value xsi:type="PriorityMotion">')
            for e, v in [("Name", "low battery"), ("Port", "Battery"), ("CompareType", "LessThanOrEqualTo"),
                         ("Value", 223), ("Address", -1)]:
                L.append(f"        <{e}>{v}</{e}>")
            L.append("      </Value>")
        L.append("    </DictionaryEntry>")
    L.append("  </PriorityMotionCollection>")
    for e, v in [("PictureFileName", ""), ("LinkFileList", ""), ("ConvertFileList", ""), ("ProjectTitle", "rcb4 test"),
                 ("FileName", r"C:\robots\three_motions.h4p"), ("Path", r"C:\robots"), ("Name", "three_motions")]:
        L.append(f"  <{e}>{v}</{e}>" if v else f"  <{e} />")
    L.append("  <Anchors />")
    L.append("  <SoundDeviceNumber>-1</SoundDeviceNumber>")
    L.append("</Rcb4>")
    return "\r\n".join(L).replace("\r\n", "\n").replace("\n", "\r\n")


def trims():
    L = ['<?xml version="1.0"?>', f'<ArrayOfDictionaryEntry {XSI}>']
    for k in range(35):
        name, trim = SERVOS.get(k, (f"servo{k}", 0))
        L.append("  <DictionaryEntry>")
        L.append(f'    <Key xsi:type="xsd:string">{name}</Key>')
        L.append(f'    <Value xsi:type="PositionData">')
        for e, v in [("Name", name), ("ID", k // 2), ("DeviceNumber", k), ("Trim", trim * 2 if trim else 0),
                     ("Position", 7500)]:
            L.append(f"      <{e}>{v}</{e}>")
        L.append("    </Value>")
        L.append("  </DictionaryEntry>")
    L.append("</ArrayOfDictionaryEntry>")
    return "\r\n".join(L).replace("\r\n", "\n").replace("\n", "\r\n")


for name, content in [("three_motions.h4p", project(0x0B80)), ("three_motions_2_0.h4p", project(0x0BB8)),
                      ("trims.h4t", trims())]:
    with open(os.path.join(HERE, name), "w", newline="") as f:
        f.write(content)
