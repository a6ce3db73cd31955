"""Short reprs for messages."""


def brief(value, width=60):
    """``repr(value)``, or where longer than ``width`` its start cut after the last separator
    (space, comma, bracket, '=') that fits and marked with "…": never mid-token, never silent."""
    text = repr(value)
    if len(text) <= width:
        return text
    head = text[:width - 1]
    cut = max(head.rfind(c) for c in " ,([{=")
    return (head[:cut + 1] if cut > width // 2 else head).rstrip() + "…"
