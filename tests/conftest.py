import pytest


@pytest.fixture
def test_name(request):
    """The test's node id, used to name its VCD and build directory."""
    return request.node.name
