"""Generates the snooker scene's ball textures (equirectangular, u = longitude,
v = latitude): a white ball with a coloured band and a number in a white disc on it.
Run from this directory: python3 make_balls.py (needs Pillow). The PNGs it writes are
committed; this script is how they were made."""
from PIL import Image, ImageDraw, ImageFont

W, H = 256, 128
BALLS = {"ball9.png": ((230, 190, 20), "9"), "ball12.png": ((120, 30, 140), "12"), "ball14.png": ((20, 120, 40), "14")}
for name, (colour, number) in BALLS.items():
    img = Image.new("RGB", (W, H), (235, 232, 222))
    d = ImageDraw.Draw(img)
    d.rectangle([0, int(H * 0.3), W, int(H * 0.7)], fill=colour)
    for cx in (W // 4, 3 * W // 4):
        d.ellipse([cx - 16, H // 2 - 16, cx + 16, H // 2 + 16], fill=(240, 238, 230))
        font = ImageFont.load_default(size=22)
        d.text((cx, H // 2), number, fill=(15, 15, 15), font=font, anchor="mm")
    img.save(name, optimize=True)
