"""``stewartid identify``: the run behind the command (:mod:`.run`) and the report of
``--report`` (:mod:`.report`; its data in :mod:`.records`, its text, figures and drawings in
:mod:`.text`, :mod:`.figures` and :mod:`.method_figures`)."""
