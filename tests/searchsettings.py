"""A search small enough for a test, as the settings file ``optimise --config`` reads."""


def small_search(workers=1):
    """Settings text: a 0.5° verification grid, a few generations of a small population."""
    return (
        f"\n[workspace]\nstep_deg = 0.5\n[search]\npopsize = 5\nmaxiter = 8\nworkers = {workers}\n"
    )


#: The small search on one worker.
SMALL_SEARCH = small_search()


def write_settings(folder, text=SMALL_SEARCH):
    """Write ``text`` to ``folder/settings.toml``; returns its path as a string."""
    path = folder / "settings.toml"
    path.write_text(text, encoding="utf-8")
    return str(path)
