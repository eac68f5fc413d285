#!/usr/bin/python3
"""Writes the HTH4 test files of this folder, in HeartToHeart4's schema (hth4-files.md §2, §6), by
hand and independently of rcb4's writer: the project three_motions.h4p (HTH4 2.2+ layout), the same
project in the 2.0-2.1 layout (three_motions_2_0.h4p), a trim file (trims.h4t) and flowcharts
(wave_twice.xml in the new schema and wave_twice_old.xml in the old, §5.7; wait_and_call.xml). The values are
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


def guid(kind, n):
    return f"{kind}0000000-0000-4000-8000-{n:012d}"


def flowchart_new(blocks, lines):
    """A new-schema flowchart (hth4-files.md §5.1, §5.7): blocks (name, base, start, frames, [(line, Begin|End)]),
    lines (n, mode)."""
    L = ['<?xml version="1.0"?>', f'<CanvasData {XSI}>', "  <Name>canvas</Name>",
         "  <Size>", "    <Width>640</Width>", "    <Height>480</Height>", "  </Size>", "  <GridSize>8</GridSize>", "  <Lines>"]
    for n, mode in lines:
        L += ['    <anyType xsi:type="LineData">', f"      <GUID>{guid('a', n)}</GUID>", "      <Path>",
              "        <Point>", "          <X>40</X>", "          <Y>64</Y>", "        </Point>", "      </Path>",
              f"      <ConnectMode>{mode}</ConnectMode>", "    </anyType>"]
    L += ["  </Lines>", "  <Activities>"]
    for i, (name, base, start, frames, conns) in enumerate(blocks):
        L += ['    <anyType xsi:type="ActivityData">', f"      <Name>{name}</Name>", f"      <GUID>{guid('b', i + 1)}</GUID>",
              "      <Location>", f"        <X>8</X>", f"        <Y>{16 + 80 * i}</Y>", "      </Location>",
              "      <Size>", "        <Width>64</Width>", "        <Height>48</Height>", "      </Size>",
              f"      <Text>{name}</Text>", "      <BackColorText>WhiteSmoke</BackColorText>",
              f"      <MotionFlag>{'Start' if start else 'None'}</MotionFlag>", f"      <BaseName>{base}</BaseName>",
              f"      <Description>{base}</Description>", "      <Group>Set</Group>",
              f"      <ConnectedGuids>{','.join(guid('a', n) for n, _ in conns)}</ConnectedGuids>",
              f"      <ConnectTypes>{','.join(t + 'Connect' for _, t in conns)}</ConnectTypes>", "      <ProgramCode>"]
        L += [f'        <anyType xsi:type="xsd:string">{text(f)}</anyType>' for f in frames]
        L += ["      </ProgramCode>", f"      <Hint>{base}</Hint>", "    </anyType>"]
    L += ["  </Activities>", "  <BackColorText>buttonface</BackColorText>", "</CanvasData>"]
    return "\r\n".join(L)


def flowchart_old(blocks, lines):
    """The old schema (§5.1, §5.3): activities and lines mixed, four connection slots (top, bottom, left,
    right) per block, PriorityList labelling them (04 True, 01 False)."""
    zero = "00000000-0000-0000-0000-000000000000"
    L = ['<?xml version="1.0"?>', f'<ArrayOfAnyType {XSI}>']
    for i, (name, base, start, frames, slots) in enumerate(blocks):
        L += ['  <anyType xsi:type="ActivityData">', f"    <Name>{name}</Name>", f"    <GUID>{guid('b', i + 1)}</GUID>",
              "    <Location>", "      <X>8</X>", f"      <Y>{16 + 80 * i}</Y>", "    </Location>", "    <Size>",
              "      <Width>64</Width>", "      <Height>48</Height>", "    </Size>",
              f"    <MotionFlag>{'Start' if start else 'None'}</MotionFlag>", "    <PriorityList>",
              f'      <anyType xsi:type="xsd:string">{" ".join(f"{lab:02X}" for _, _, lab in slots)}</anyType>',
              "    </PriorityList>", f"    <BaseName>{base}</BaseName>", f"    <Description>{base}</Description>",
              "    <Group>Set</Group>", "    <Path />",
              f"    <ConnectedGuids>{','.join(guid('a', n) if n else zero for n, _, _ in slots)}</ConnectedGuids>",
              f"    <ConnectTypes>{','.join(t + 'Connect' if n else 'NotConnected' for n, t, _ in slots)}</ConnectTypes>",
              "    <ProgramCode>"]
        L += [f'      <anyType xsi:type="xsd:string">{text(f)}</anyType>' for f in frames]
        L += ["    </ProgramCode>", "  </anyType>"]
    for n in lines:
        L += ['  <anyType xsi:type="LineData">', "    <Name />", "    <StartPoint>", "      <X>40</X>", "      <Y>64</Y>",
              "    </StartPoint>", "    <EndPoint>", "      <X>40</X>", "      <Y>96</Y>", "    </EndPoint>",
              f"    <GUID>{guid('a', n)}</GUID>", "    <LineType>Straight</LineType>", "  </anyType>"]
    L.append("</ArrayOfAnyType>")
    return "\r\n".join(L)


# hth4-files.md §5.7: SetCounter1 (Start) -> Pos2 -> Loop3; Loop3 False -> Pos2, True -> Pos4. The
# loop's JUMP waits for its target (FF FF FF, its SUM over the placeholder: 14).
SET_COUNTER = [0x08, 0x00, 0x02, 0x57, 0x04, 0x00, 0x02, 0x67]
POS2 = [0x0D, 0x10, 0x0C, 0x00, 0x00, 0x00, 0x00, 0x14, 0x78, 0x1E, 0x20, 0x1C, 0x0F]
LOOP = [[0x08, 0x07, 0x02, 0x57, 0x04, 0x00, 0x01, 0x6D], [0x07, 0x0B, 0xFF, 0xFF, 0xFF, 0x05, 0x14]]
POS4 = [0x0D, 0x10, 0x0C, 0x00, 0x00, 0x00, 0x00, 0x1E, 0x4C, 0x1D, 0x4C, 0x1D, 0x19]
WAVE_NEW = flowchart_new(
    [("SetCounter1", "SetCounter", True, [SET_COUNTER], [(1, "Begin")]),
     ("Pos2", "Pos", False, [POS2], [(1, "End"), (2, "Begin"), (3, "End")]),
     ("Loop3", "Loop", False, LOOP, [(2, "End"), (3, "Begin"), (4, "Begin")]),
     ("Pos4", "Pos", False, [POS4], [(4, "End")])],
    [(1, "Normal"), (2, "Normal"), (3, "False"), (4, "True")])
WAVE_OLD = flowchart_old(
    [("SetCounter1", "SetCounter", True, [SET_COUNTER], [(0, "", 0), (1, "Begin", 0), (0, "", 0), (0, "", 0)]),
     ("Pos2", "Pos", False, [POS2], [(1, "End", 0), (2, "Begin", 0), (3, "End", 0), (0, "", 0)]),
     ("Loop3", "Loop", False, LOOP, [(2, "End", 0), (3, "Begin", 1), (0, "", 0), (4, "Begin", 4)]),
     ("Pos4", "Pos", False, [POS4], [(4, "End", 0), (0, "", 0), (0, "", 0), (0, "", 0)])],
    [1, 2, 3, 4])
# A Wait (0.8 s: MOV 8 -> timer 0; SUB timer 0 - 0x8000; JUMP back to the SUB while it is not 0,
# its target left from an older build at 0x0012AB) then a MotionJump calling motion 2 of the
# 2.0-2.1 layout (0x0013B8), then a pose: §5.5's patterns.
WAIT = [[0x09, 0x00, 0x02, 0x3C, 0x00, 0x00, 0x08, 0x00, 0x4F], [0x09, 0x07, 0x82, 0x3C, 0x00, 0x00, 0x00, 0x80, 0x4E],
        frame(0x0B, 0xAB, 0x12, 0x00, 0x04)]
CALL2 = [frame(0x0C, 0xB8, 0x13, 0x00, 0x00)]
WAIT_CALL = flowchart_new(
    [("Pos1", "Pos", True, [POS2], [(1, "Begin")]),
     ("Wait2", "Wait", False, WAIT, [(1, "End"), (2, "Begin")]),
     ("MotionJump3", "MotionJump", False, CALL2, [(2, "End"), (3, "Begin")]),
     ("Pos4", "Pos", False, [POS4], [(3, "End")])],
    [(1, "Normal"), (2, "Normal"), (3, "Normal")])

for name, content in [("three_motions.h4p", project(0x0B80)), ("three_motions_2_0.h4p", project(0x0BB8)),
                      ("trims.h4t", trims()), ("wave_twice.xml", WAVE_NEW), ("wave_twice_old.xml", WAVE_OLD),
                      ("wait_and_call.xml", WAIT_CALL)]:
    with open(os.path.join(HERE, name), "w", newline="") as f:
        f.write(content)
