from setuptools import find_packages, setup

package_name = 'multilift_example_leader'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='multilift developers',
    maintainer_email='dev@multilift.dev',
    description='A leader controller node of your own for multilift.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'leader = multilift_example_leader.leader:main',
        ],
    },
)
