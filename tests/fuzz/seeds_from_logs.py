#!/usr/bin/env python3
"""Seeds for the `messages` fuzz target from the project's own LCM logs (e.g. those the service
tests write): one file per message type (by fingerprint) and channel, the smallest of each, at
most MAX_BYTES long; plus an image_t carrying each image of tests/fuzz/corpus/image (made from
an image_t fingerprint found in the logs). Usage: seeds_from_logs.py OUT_DIR LOG...
"""
import os
import struct
import sys

SYNC = 0xEDA1DA01
MAX_BYTES = 4096


def events(path):
    with open(path, "rb") as f:
        data = f.read()
    pos = 0
    while pos + 28 <= len(data):
        sync, _, _, channel_len, data_len = struct.unpack(">IqqII", data[pos:pos + 28])
        if sync != SYNC:
            return
        pos += 28
        channel = data[pos:pos + channel_len].decode("ascii", "replace")
        pos += channel_len
        yield channel, data[pos:pos + data_len]
        pos += data_len


def image_message(fingerprint, pixels, pixel_format):
    camera = b"left\0"
    return (fingerprint + struct.pack(">qqi", 1, 1, len(camera)) + camera +
            struct.pack(">iiibi", 32, 24, 0, pixel_format, len(pixels)) + pixels)


def main():
    out, logs = sys.argv[1], sys.argv[2:]
    os.makedirs(out, exist_ok=True)
    smallest = {}
    image_fingerprint = None
    for log in logs:
        for channel, payload in events(log):
            if channel.startswith("CAMERA") or channel.startswith("SNAPSHOT"):
                image_fingerprint = payload[:8]
            key = (channel, payload[:8])
            if len(payload) <= MAX_BYTES and (key not in smallest or len(payload) < len(smallest[key])):
                smallest[key] = payload
    for (channel, _), payload in sorted(smallest.items()):
        name = "%s_%d" % (channel.lower(), len(payload))
        with open(os.path.join(out, name), "wb") as f:
            f.write(payload)
    if image_fingerprint:
        images = os.path.join(os.path.dirname(out.rstrip("/")), "image")
        for name in sorted(os.listdir(images)):
            pixels = open(os.path.join(images, name), "rb").read()
            fmt = 5 if name.endswith(".png") else 4
            with open(os.path.join(out, "image_t_" + name), "wb") as f:
                f.write(image_message(image_fingerprint, pixels, fmt))
    print("%d seeds in %s" % (len(os.listdir(out)), out))


if __name__ == "__main__":
    main()
