"""Inline SVG pictures drawn from our own data (no plotting service, no network)."""

from __future__ import annotations

from markupsafe import Markup, escape


def intervals_svg(points: list[tuple[float, float]], limit: float | None, title: str,
                  width: int = 560, height: int = 180) -> Markup:
    """Gaps between messages (y) over simulation time (x), with the allowed gap as a line."""
    if not points:
        return Markup("")
    pad_l, pad_b, pad_t, pad_r = 44, 24, 10, 8
    xs = [p[0] for p in points]
    x0, x1 = min(xs), max(xs) if max(xs) > min(xs) else min(xs) + 1
    top = max([p[1] for p in points] + [limit or 0]) * 1.15 or 1.0
    w, h = width - pad_l - pad_r, height - pad_t - pad_b

    def sx(x: float) -> float:
        return pad_l + (x - x0) / (x1 - x0) * w

    def sy(y: float) -> float:
        return pad_t + h - y / top * h

    path = " ".join(f"{'M' if i == 0 else 'L'}{sx(x):.1f},{sy(y):.1f}"
                    for i, (x, y) in enumerate(points))
    over = [(x, y) for x, y in points if limit is not None and y > limit + 1e-9]
    parts = [
        f'<svg xmlns="http://www.w3.org/2000/svg" class="chart" width="{width}" '
        f'height="{height}" viewBox="0 0 {width} {height}" role="img" direction="ltr">',
        f"<title>{escape(title)}</title>",
        f'<rect x="{pad_l}" y="{pad_t}" width="{w}" height="{h}" fill="#fafafa" '
        f'stroke="#d0d7de"/>',
        f'<path d="{path}" fill="none" stroke="#0969da" stroke-width="1.2"/>',
    ]
    if limit is not None:
        parts.append(f'<line class="limit" x1="{pad_l}" x2="{pad_l + w}" y1="{sy(limit):.1f}" '
                     f'y2="{sy(limit):.1f}" stroke="#cf222e" stroke-dasharray="4 3"/>')
        parts.append(f'<text x="{pad_l - 4}" y="{sy(limit) + 4:.1f}" font-size="10" '
                     f'text-anchor="end" fill="#cf222e">{limit:g} s</text>')
    parts += [f'<circle cx="{sx(x):.1f}" cy="{sy(y):.1f}" r="2.5" fill="#cf222e"/>'
              for x, y in over]
    parts += [
        f'<text x="{pad_l - 4}" y="{pad_t + 8}" font-size="10" text-anchor="end">'
        f"{top:.2g} s</text>",
        f'<text x="{pad_l}" y="{height - 6}" font-size="10">{x0:.1f} s</text>',
        f'<text x="{pad_l + w}" y="{height - 6}" font-size="10" text-anchor="end">'
        f"{x1:.1f} s</text>",
        "</svg>",
    ]
    return Markup("\n".join(parts))
